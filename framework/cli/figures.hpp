#pragma once
// The figures and the animation of `redres run` and `redres compare`: plot_run.py found before a run, run without a
// shell, its failures reported with what was written; and the files a figure step added to an output directory.

#include <cstdint>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

namespace redres::cli {

// What renders the figures. Found before a run, so that a missing python3 or script fails at once instead of
// after a long run.
struct Plotter {
  std::filesystem::path python;
  std::filesystem::path script;
  std::string request;  // what asked for the figures, for the messages: "--plots", "compare", ...
};

// Figures that were asked for but cannot be made are an error (exit code 2), never a warning: a script or CI job
// that asked for them must not pass without them.
Plotter find_plotter(std::string request);

// Renders figures with plot_run.py; `args` are the script's arguments, `outputs` where the run's data went (the
// data stays valid when only the figures fail). Throws when the script cannot run or fails.
void render_plots(const Plotter& p, std::vector<std::string> args, bool quiet, const std::string& outputs);

// The animation of a run: plot_run.py --animate DIR writes DIR/animation.mp4 (ffmpeg on PATH) or else
// DIR/animation.gif. An animation left by an earlier run into DIR is removed first, so that the file found
// afterwards is this run's; it is an error if there is none.
std::filesystem::path render_animation(const Plotter& p, const std::filesystem::path& dir, bool quiet,
                                       const std::string& outputs);

// The regular files of a directory with their modification times and sizes, to tell which files a figure step
// wrote.
using Listing = std::vector<std::tuple<std::string, std::filesystem::file_time_type, std::uintmax_t>>;
Listing list_files(const std::filesystem::path& dir);

// Adds the files that are new or changed since `before` to the directory's manifest: the figures just made, which
// the next run into the directory removes if it does not make them again.
void record_new_files(const std::filesystem::path& dir, const Listing& before);

}  // namespace redres::cli
