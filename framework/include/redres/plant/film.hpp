#pragma once
/// @file
/// Filming a run (docs/plant.md, "Filming a run"): film() renders recorded frames of a MuJoCo model offscreen, with
/// MuJoCo's own renderer on an EGL context of Mesa's surfaceless platform (no X server, no window), and writes an MP4
/// through `ffmpeg` when it is on PATH, else PNG frames and an animated GIF. It runs after a run, from the frames the
/// run recorded, never inside the control loop: a frame costs tens of milliseconds in software rendering.
///
/// This header includes no MuJoCo or EGL header. Without MuJoCo (film_available() false) film() throws.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace redres {

/// How film() renders and encodes.
struct FilmOptions {
  int width = 800;   //!< pixels (an MP4 rounds an odd size down to an even one)
  int height = 600;  //!< pixels
  /// Frames per second of simulated time: the frames given are played at this rate (film_times() gives the times a
  /// run is decimated to).
  double fps = 25.0;
  /// kAuto: `film.mp4` when `ffmpeg` is on PATH, else PNG frames and `film.gif`; kFrames: always PNG frames and GIF.
  enum class Encoder { kAuto, kFrames };
  Encoder encoder = Encoder::kAuto;
};

/// One frame: the simulated time, MuJoCo's qpos (size nq) and the world positions of the model's mocap bodies (3 x
/// nmocap, in the model's order: the moving obstacles).
struct FilmFrame {
  double t = 0.0;
  Eigen::VectorXd qpos;
  Eigen::Matrix3Xd mocap_pos;
};

/// What film() wrote.
struct FilmReport {
  std::filesystem::path file;        //!< dir/film.mp4 or dir/film.gif
  std::filesystem::path frames_dir;  //!< dir/film_frames when PNG frames were written, else empty
  int frames = 0;
  double seconds_per_frame = 0.0;         //!< wall time of rendering and encoding, per frame
  double render_seconds_per_frame = 0.0;  //!< of which rendering (MuJoCo's scene, drawing, reading the pixels back)
  double wall_seconds = 0.0;              //!< wall time of the whole film() call
  std::string format;                     //!< "mp4" or "gif"
};

/// The frame times of a run of `duration` seconds at `fps`: 0, 1/fps, 2/fps, ... and `duration` itself (once, even
/// when it is not a multiple of 1/fps). std::invalid_argument for a negative or non-finite duration, or an fps that
/// is not positive and finite.
[[nodiscard]] std::vector<double> film_times(double duration, double fps);

/// Renders `frames` of the model `mjcf` (MJCF text, loaded through MuJoCo's virtual file system as MujocoModel is)
/// into the existing directory `dir`, and returns what it wrote. One fixed camera for the whole film frames the robot
/// and the mocap bodies over every frame; each frame shows its simulated time. `progress`, when given, is called
/// after each frame with the number done and the total.
///
/// Files: `dir/film.mp4` (through ffmpeg), or `dir/film_frames/frame_00000.png ...` and `dir/film.gif`. Nothing that
/// exists is replaced: film() refuses before rendering when its output exists (a file, a directory or a symbolic
/// link), and a failure removes what it had written. Throws std::invalid_argument for bad options or frames (a qpos
/// or mocap size that is not the model's, no frames), std::runtime_error naming the step that failed (the EGL
/// display, initialisation or context, MuJoCo's rendering context, writing a file, ffmpeg's exit status with the end
/// of its messages; MuJoCo's own errors, which redres makes exceptions).
FilmReport film(const std::string& mjcf, const std::vector<FilmFrame>& frames, const std::filesystem::path& dir,
                const FilmOptions& options, const std::function<void(int done, int total)>& progress = {});

/// Whether this build of redres can film (it was built with MuJoCo). Whether the machine can render (an EGL driver)
/// shows only when film() runs.
[[nodiscard]] bool film_available() noexcept;

}  // namespace redres
