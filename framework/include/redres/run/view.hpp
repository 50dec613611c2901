#pragma once
/// @file
/// The interactive 3-D replay of finished runs (`redres view`, `redres run --view`, `redres compare --view`;
/// docs/viewer.md): one self-contained HTML file that draws the robot, the obstacles, the desired path and the end
/// effector's trace with three.js (Debian's libjs-three, inlined when the file is written), with plots of the run
/// synchronised with its time cursor. Made from a run's directory alone (summary.json, frames.csv, trajectory.csv),
/// so that a run can be viewed wherever its directory goes.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace redres {

/// What to write.
struct ViewOptions {
  /// The most rows of trajectory.csv the plots keep (every k-th row, and the last). The 3-D frames are the rows of
  /// frames.csv (at most 500, docs/output_formats.md).
  int max_plot_points = 2000;
  /// The page's title; empty: the runs' labels.
  std::string title;
  /// Where Debian's libjs-three is (`build/three.min.js`, `examples/js/controls/OrbitControls.js`); empty: the
  /// environment's REDRES_THREE_DIR, else /usr/share/javascript/three.
  std::filesystem::path three_dir;
};

/// What was written.
struct ViewReport {
  std::filesystem::path file;
  std::uintmax_t bytes = 0;          //!< the file's size
  int runs = 0;                      //!< runs in it
  int frames = 0;                    //!< 3-D frames (of the longest run)
  int bodies = 0;                    //!< robot shapes and obstacles drawn (all runs)
  int visuals = 0;                   //!< visual elements drawn (all runs)
  std::size_t visual_triangles = 0;  //!< triangles of the visual meshes (each mesh once)
  std::string title;                 //!< the page's title
  std::vector<std::string> notes;    //!< what could not be drawn as recorded (e.g. a hull whose mesh is gone)
};

/// The page's data for the runs in `run_dirs` (each holding summary.json, frames.csv and trajectory.csv), as JSON
/// text (docs/viewer.md, "The page's data"). std::runtime_error naming the directory and the file when one is
/// missing or unreadable (a run written with `--record none` or `--format hdf5` says so).
[[nodiscard]] std::string view_data(const std::vector<std::filesystem::path>& run_dirs, const ViewOptions& options,
                                    ViewReport& report);

/// The whole page: the viewer's HTML, script and style, three.js and its orbit controls, and view_data().
/// std::runtime_error when libjs-three is not found (naming the Debian package) or a run cannot be read.
[[nodiscard]] std::string view_html(const std::vector<std::filesystem::path>& run_dirs, const ViewOptions& options,
                                    ViewReport& report);

/// Writes view_html() to `file` through a StagedFile (never through a symbolic link; an existing file is replaced
/// only when `replace` is true, otherwise refused). Returns the report.
ViewReport write_view(const std::vector<std::filesystem::path>& run_dirs, const std::filesystem::path& file,
                      const ViewOptions& options, bool replace);

}  // namespace redres
