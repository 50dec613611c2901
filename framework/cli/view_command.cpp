// `redres view RUN_DIR...`: the interactive 3-D replay of finished runs in one self-contained HTML file
// (run/view.hpp, docs/viewer.md). `redres run --view` and `redres compare --view` write it after their runs.

#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "view_command.hpp"

#include "commands.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/view.hpp"

namespace redres::cli {

namespace {

namespace fs = std::filesystem;

struct ViewCommandOptions {
  std::vector<std::string> dirs;
  std::string out;
  std::string title;
  int row = -1;
  int max_plot_points = 2000;
  bool quiet = false;
};

// A sweep's directory with --row K stands for its kept run runs/K (`runs = true` in the sweep file).
fs::path run_directory(const std::string& dir, int row) {
  const fs::path d(dir);
  if (row >= 0) {
    const fs::path r = d / "runs" / std::to_string(row);
    if (!fs::exists(r / "summary.json")) {
      throw std::runtime_error("view: " + r.string() + " holds no run: --row K needs a sweep that kept its runs (" +
                               "`runs = true` in the sweep file, or `redres sweep --runs`)");
    }
    if (!fs::exists(r / "frames.csv")) {
      throw std::runtime_error("view: " + r.string() +
                               " has no rows to replay: the sweep kept its runs' summaries "
                               "only; set [output] record = \"all\" (or \"every=N\") in the sweep file");
    }
    return r;
  }
  if (!fs::exists(d / "summary.json") && fs::exists(d / "sweep.csv")) {
    throw std::runtime_error("view: " + dir +
                             " is a sweep's directory: name one of its rows with --row K (its runs/K)");
  }
  return d;
}

}  // namespace

void print_view_report(const ViewReport& report, bool quiet) {
  for (const std::string& note : report.notes) std::cerr << "view: " << note << "\n";
  if (quiet) return;
  std::cout << "view: " << report.file.string() << " (" << report.runs << (report.runs == 1 ? " run, " : " runs, ")
            << report.frames << " frames, " << report.bodies << " bodies, " << (report.bytes + 512) / 1024
            << " KiB): open it in a browser\n";
}

ViewReport write_run_view(const std::vector<fs::path>& dirs, const fs::path& out_dir, const ViewOptions& options) {
  // An earlier view.html that redres wrote (listed in the manifest, unchanged since) is replaced; anything else
  // of that name is refused.
  const fs::path file = out_dir / "view.html";
  const bool ours = remove_earlier_output(out_dir, "view.html");
  ViewReport report = write_view(dirs, file, options, ours);
  add_to_output_manifest(out_dir, {"view.html"});
  return report;
}

void add_view_command(CLI::App& app, Action& action) {
  auto opts = std::make_shared<ViewCommandOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view", "Write view.html: the runs replayed in 3-D with their plots, one file for any browser (docs/viewer.md)");
  cmd->add_option("RUN_DIR", opts->dirs, "run directories (redres run --out DIR); several are overlaid for comparison")
      ->required();
  cmd->add_option("--out", opts->out,
                  "the HTML file to write (default: RUN_DIR/view.html for one run; required for several)");
  cmd->add_option("--row", opts->row, "RUN_DIR is a sweep's directory: view its kept run runs/ROW")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--title", opts->title, "the page's title (default: the runs' labels)");
  cmd->add_option("--max-plot-points", opts->max_plot_points,
                  "the most rows of trajectory.csv each plot keeps (default 2000; the 3-D frames are frames.csv's)")
      ->check(CLI::Range(2, 1000000));
  cmd->add_flag("--quiet", opts->quiet, "print nothing but errors");
  cmd->callback([opts, &action] {
    action = [opts] {
      if (opts->row >= 0 && opts->dirs.size() != 1)
        throw std::invalid_argument("view: --row takes one sweep directory");
      std::vector<fs::path> dirs;
      for (const std::string& d : opts->dirs) dirs.push_back(run_directory(d, opts->row));
      ViewOptions options;
      options.title = opts->title;
      options.max_plot_points = opts->max_plot_points;
      ViewReport report;
      if (!opts->out.empty()) {
        report = write_view(dirs, opts->out, options, false);
      } else if (dirs.size() == 1) {
        report = write_run_view(dirs, dirs.front(), options);
      } else {
        throw std::invalid_argument("view: several runs go into one file: name it with --out FILE");
      }
      print_view_report(report, opts->quiet);
      return kExitOk;
    };
  });
}

}  // namespace redres::cli
