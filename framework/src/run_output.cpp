#include "redres/run_output.hpp"

#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace redres {

void write_run(const RunResult& run, const RunSummary& summary, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const Trajectory& tr = run.trajectory;
  const std::filesystem::path csv = dir / "trajectory.csv";
  std::FILE* f = std::fopen(csv.string().c_str(), "w");
  if (f == nullptr) throw std::runtime_error("cannot write " + csv.string());
  const auto& cols = tr.columns();
  for (std::size_t c = 0; c < cols.size(); ++c) std::fprintf(f, "%s%s", c ? "," : "", cols[c].c_str());
  std::fputc('\n', f);
  for (std::size_t r = 0; r < tr.size(); ++r) {
    const double* row = tr.row(r);
    for (std::size_t c = 0; c < tr.width(); ++c) std::fprintf(f, "%s%.12g", c ? "," : "", row[c]);
    std::fputc('\n', f);
  }
  if (std::fclose(f) != 0) throw std::runtime_error("cannot write " + csv.string());
  std::ofstream js(dir / "summary.json");
  js << to_json(summary) << "\n";
  if (!js) throw std::runtime_error("cannot write " + (dir / "summary.json").string());
}

}  // namespace redres
