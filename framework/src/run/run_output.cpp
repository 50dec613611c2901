#include "redres/run/run_output.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "redres/common/error.hpp"
#include "redres/model/kinematics.hpp"

namespace redres {

namespace {

// A table as comma-separated text with one header line. Numbers are written by std::to_chars in their shortest
// round-trip form (reading the text back gives the same doubles, bit for bit), into a buffer written in large
// blocks: several times faster than printf("%.17g").
// `shown` is the name errors give (the final name of a staged file).
void write_csv(const Trajectory& table, const std::filesystem::path& file, const std::filesystem::path& shown,
               std::size_t every = 1) {
  std::FILE* f = std::fopen(file.string().c_str(), "w");
  if (f == nullptr) throw std::runtime_error("cannot write " + shown.string());
  constexpr std::size_t kBlock = 1 << 16;
  std::string out;
  out.reserve(kBlock + 4096);
  bool ok = true;
  const auto flush = [&] {
    ok = ok && std::fwrite(out.data(), 1, out.size(), f) == out.size();
    out.clear();
  };
  const auto& cols = table.columns();
  for (std::size_t c = 0; c < cols.size(); ++c) (out += c ? "," : "") += cols[c];
  out += '\n';
  char number[64];
  for (std::size_t r = 0; r < table.size(); ++r) {
    if (r % every != 0 && r + 1 != table.size()) continue;  // every N-th row, and the last
    const double* row = table.row(r);
    for (std::size_t c = 0; c < table.width(); ++c) {
      if (c != 0) out += ',';
      const auto end = std::to_chars(number, number + sizeof(number), row[c]).ptr;
      out.append(number, end);
    }
    out += '\n';
    if (out.size() >= kBlock) flush();
  }
  flush();
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error("cannot write " + shown.string());
}

// Where `file` is written before it is renamed into place: beside it (rename is atomic within a directory), hidden,
// and unique to this process.
std::filesystem::path staging_path(const std::filesystem::path& file) {
  return file.parent_path() / ("." + file.filename().string() + ".tmp." + std::to_string(::getpid()));
}

// Columns per joint in frames.csv: origin, then the rotation row by row.
constexpr std::size_t kFrameColumns = 12;

}  // namespace

Trajectory joint_frames(const RobotModel& robot, const Trajectory& run, std::size_t max_rows) {
  REDRES_REQUIRE(max_rows >= 2, "joint_frames", "max_rows >= 2");
  const int n = robot.dof();
  const auto joints = static_cast<std::size_t>(n);
  std::vector<std::string> columns = {"t"};
  std::vector<std::size_t> c_theta;
  for (int j = 1; j <= n; ++j) {
    const std::string J = std::to_string(j);
    for (const char* c : {"_x", "_y", "_z", "_r11", "_r12", "_r13", "_r21", "_r22", "_r23", "_r31", "_r32", "_r33"}) {
      columns.push_back("joint_" + J + c);
    }
    c_theta.push_back(run.column("theta_" + J));
  }
  for (const char* axis : {"ee_x", "ee_y", "ee_z"}) columns.emplace_back(axis);
  const std::size_t rows = run.size();
  // Stride k = ceil((rows - 1) / (max_rows - 1)) keeps floor((rows - 1) / k) + 1 <= max_rows rows, plus the last
  // one when the stride does not land on it, which then had room (floor((rows - 1) / k) <= max_rows - 2).
  const std::size_t stride = rows <= max_rows ? 1 : (rows - 1 + max_rows - 2) / (max_rows - 1);
  std::vector<std::size_t> kept;
  for (std::size_t r = 0; r < rows; r += stride) kept.push_back(r);
  if (rows > 0 && kept.back() != rows - 1) kept.push_back(rows - 1);
  Trajectory out(std::move(columns), kept.size());
  const std::size_t c_t = run.column("t");
  KinematicsData k(robot);
  Eigen::VectorXd theta(n);
  const auto put = [](double* at, const Eigen::Vector3d& p) {
    at[0] = p.x();
    at[1] = p.y();
    at[2] = p.z();
  };
  for (const std::size_t r : kept) {
    for (std::size_t j = 0; j < joints; ++j) theta(static_cast<Eigen::Index>(j)) = run(r, c_theta[j]);
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    double* row = out.append_row();
    row[0] = run(r, c_t);
    for (std::size_t j = 0; j < joints; ++j) {
      const Eigen::Isometry3d& T = k.link_frames[j];
      double* at = row + 1 + kFrameColumns * j;
      put(at, T.translation());
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) at[3 + 3 * a + b] = T.linear()(a, b);
      }
    }
    put(row + 1 + kFrameColumns * joints, k.ee_pose.translation());
  }
  return out;
}

namespace {

bool manifest_name_ok(const std::string& name) {
  return !name.empty() && name.find('/') == std::string::npos && name[0] != '.';
}

void write_manifest(const std::filesystem::path& dir, const std::vector<std::string>& names) {
  std::string text =
      "# the files the last redres run wrote into this directory; the next run removes those it does not write "
      "again\n";
  for (const auto& n : names) text += n + "\n";
  write_text_file(dir / kOutputManifest, text);
}

}  // namespace

void write_text_file(const std::filesystem::path& file, const std::string& text) {
  const std::filesystem::path tmp = staging_path(file);
  std::ofstream out(tmp);
  out << text;
  out.close();
  if (!out) {
    const int e = errno;
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("cannot write " + file.string() + ": " + std::strerror(e));
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("cannot write " + file.string() + ": " + ec.message());
  }
}

std::vector<std::string> read_output_manifest(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  std::ifstream in(dir / kOutputManifest);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (manifest_name_ok(line)) names.push_back(line);
  }
  return names;
}

void add_to_output_manifest(const std::filesystem::path& dir, const std::vector<std::string>& names) {
  std::vector<std::string> all = read_output_manifest(dir);
  for (const auto& n : names) {
    if (manifest_name_ok(n) && std::find(all.begin(), all.end(), n) == all.end()) all.push_back(n);
  }
  write_manifest(dir, all);
}

void prepare_output_dir(const std::filesystem::path& dir, const std::string& what) {
  const std::string where = what + " " + dir.string() + ": ";
  std::error_code ec;
  const auto status = std::filesystem::status(dir, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_directory(status)) {
    throw std::runtime_error(where + "exists and is not a directory");
  }
  if (!std::filesystem::exists(status)) {
    std::filesystem::create_directories(dir, ec);
    if (ec) throw std::runtime_error(where + "cannot create the directory: " + ec.message());
  }
  const std::filesystem::path probe = staging_path(dir / "probe");
  {
    std::ofstream out(probe);
    out << "probe\n";
    out.close();
    if (!out) {
      std::filesystem::remove(probe, ec);
      throw std::runtime_error(where + "cannot write into the directory (" + std::strerror(errno) + ")");
    }
  }
  std::filesystem::remove(probe, ec);
}

std::vector<std::string> write_run(const RobotModel& robot, const RunResult& run, const RunSummary& summary,
                                   const std::filesystem::path& dir, const RecordOptions& record) {
  REDRES_REQUIRE(record.every >= 1, "write_run", "record.every >= 1");
  std::filesystem::create_directories(dir);
  // Every file is written to a temporary beside it first, so that a failed write (a full disk, a read-only
  // directory) leaves the directory as it was. Then the old summary goes, the tables are renamed into place, and
  // the summary comes last: a reader that finds summary.json finds the complete tables of the same run.
  const std::filesystem::path summary_file = dir / "summary.json";
  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged;  // temporary, final
  const auto stage = [&staged](const std::filesystem::path& file) {
    staged.emplace_back(staging_path(file), file);
    return staged.back().first;
  };
  try {
    if (!record.none) {
      write_csv(run.trajectory, stage(dir / "trajectory.csv"), dir / "trajectory.csv", record.every);
      write_csv(joint_frames(robot, run.trajectory), stage(dir / "frames.csv"), dir / "frames.csv");
    }
    const std::filesystem::path js_file = stage(summary_file);
    std::ofstream js(js_file);
    js << to_json(summary) << "\n";
    js.close();
    if (!js) throw std::runtime_error("cannot write " + summary_file.string());
  } catch (...) {
    std::error_code ignored;
    for (const auto& [tmp, file] : staged) std::filesystem::remove(tmp, ignored);
    throw;
  }
  std::vector<std::string> written;
  for (const auto& [tmp, file] : staged) written.push_back(file.filename().string());
  // What an earlier run wrote and this one does not is stale: removed, before this run's files appear. A
  // directory from before manifests existed may hold tables that would not belong to a summary-only run.
  std::vector<std::string> stale = read_output_manifest(dir);
  if (record.none) stale.insert(stale.end(), {"trajectory.csv", "frames.csv"});
  std::filesystem::remove(summary_file);
  for (const auto& name : stale) {
    if (std::find(written.begin(), written.end(), name) != written.end()) continue;
    std::error_code ec;
    if (std::filesystem::is_regular_file(dir / name, ec)) std::filesystem::remove(dir / name, ec);
  }
  for (const auto& [tmp, file] : staged) std::filesystem::rename(tmp, file);  // summary.json last
  write_manifest(dir, written);
  return written;
}

}  // namespace redres
