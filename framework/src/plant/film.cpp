// film(): recorded frames of a MuJoCo model rendered offscreen with MuJoCo's renderer (film_scene.hpp) on an EGL
// context of Mesa's surfaceless platform (film_egl.hpp), encoded to an MP4 by ffmpeg or to PNG frames and a GIF
// (film_encoder.hpp). With MuJoCo (REDRES_HAVE_MUJOCO) these files include MuJoCo's, EGL's, libpng's and giflib's
// headers; without it film() throws.

#include "redres/plant/film.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#if REDRES_HAVE_MUJOCO
#include <chrono>
#include <cstdio>
#include <memory>
#include <system_error>

#include "plant/film_egl.hpp"
#include "plant/film_encoder.hpp"
#include "plant/film_scene.hpp"
#endif

namespace redres {

std::vector<double> film_times(double duration, double fps) {
  if (!std::isfinite(duration) || duration < 0.0)
    throw std::invalid_argument("film_times: the duration must be finite and not negative, not " +
                                std::to_string(duration));
  if (!std::isfinite(fps) || fps <= 0.0)
    throw std::invalid_argument("film_times: fps must be positive and finite, not " + std::to_string(fps));
  const double count = std::floor(duration * fps * (1.0 + 1e-12));
  if (count > 1e7)
    throw std::invalid_argument("film_times: " + std::to_string(duration) + " s at " + std::to_string(fps) +
                                " frames per second is more than 10 million frames");
  const auto n = static_cast<long>(count);
  std::vector<double> times;
  times.reserve(static_cast<std::size_t>(n) + 2);
  // i / fps rather than a running sum, so that the times do not drift.
  for (long i = 0; i <= n; ++i) times.push_back(static_cast<double>(i) / fps);
  // The last frame is the run's end: snapped onto it when within rounding, added after the grid otherwise.
  const double tolerance = 1e-9 * std::max(1.0, duration);
  if (duration - times.back() > tolerance)
    times.push_back(duration);
  else if (n > 0)
    times.back() = duration;
  return times;
}

#if REDRES_HAVE_MUJOCO

bool film_available() noexcept { return true; }

namespace {

using plant_detail::EglContext;
using plant_detail::Encoder;
using plant_detail::FilmModel;
using plant_detail::Renderer;

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Throws when `file` exists in any form (a dangling symbolic link included).
void require_missing(const std::filesystem::path& file) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::symlink_status(file, error);
  if (std::filesystem::exists(status) || status.type() == std::filesystem::file_type::symlink)
    throw std::runtime_error("film: " + file.string() +
                             " exists; film() replaces nothing (remove it, or film into another directory)");
}

std::string time_label(double t) {
  char text[64];
  std::snprintf(text, sizeof text, "t = %.2f s", t);
  return text;
}

}  // namespace

FilmReport film(const std::string& mjcf, const std::vector<FilmFrame>& frames, const std::filesystem::path& dir,
                const FilmOptions& options, const std::function<void(int done, int total)>& progress) {
  const Clock::time_point start = Clock::now();
  constexpr int kMaxSide = 8192;
  if (options.width < 2 || options.height < 2 || options.width > kMaxSide || options.height > kMaxSide)
    throw std::invalid_argument("film: the picture must be 2 to " + std::to_string(kMaxSide) +
                                " pixels wide and high, not " + std::to_string(options.width) + "x" +
                                std::to_string(options.height));
  if (!std::isfinite(options.fps) || options.fps <= 0.0)
    throw std::invalid_argument("film: fps must be positive and finite, not " + std::to_string(options.fps));
  if (frames.empty()) throw std::invalid_argument("film: no frames to film");
  std::error_code error;
  if (!std::filesystem::is_directory(dir, error))
    throw std::runtime_error("film: " + dir.string() + " is not an existing directory");

  plant_detail::throw_on_mujoco_errors();
  FilmModel model;
  plant_detail::load_model(mjcf, model);
  mjModel* m = model.m;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const FilmFrame& f = frames[i];
    const std::string which = "film: frame " + std::to_string(i) + " (t = " + std::to_string(f.t) + ")";
    if (f.qpos.size() != m->nq)
      throw std::invalid_argument(which + " has a qpos of " + std::to_string(f.qpos.size()) +
                                  " entries; the model's nq is " + std::to_string(m->nq));
    if (f.mocap_pos.cols() != m->nmocap)
      throw std::invalid_argument(which + " has " + std::to_string(f.mocap_pos.cols()) +
                                  " mocap positions; the model has " + std::to_string(m->nmocap) + " mocap bodies");
    if (!std::isfinite(f.t) || !f.qpos.allFinite() || !f.mocap_pos.allFinite())
      throw std::invalid_argument(which + " holds a value that is not finite");
  }

  // The encoder and its files; nothing exists yet that film() would write.
  const std::filesystem::path ffmpeg =
      options.encoder == FilmOptions::Encoder::kAuto ? plant_detail::find_on_path("ffmpeg") : std::filesystem::path();
  const bool mp4 = !ffmpeg.empty();
  // yuv420p halves the chroma in both directions: an MP4's sides are even.
  const int width = mp4 ? options.width & ~1 : options.width;
  const int height = mp4 ? options.height & ~1 : options.height;
  FilmReport report;
  report.format = mp4 ? "mp4" : "gif";
  report.file = dir / (mp4 ? "film.mp4" : "film.gif");
  if (!mp4) report.frames_dir = dir / "film_frames";
  require_missing(report.file);
  if (!mp4) require_missing(report.frames_dir);

  // The renderer: the offscreen buffer is the picture's size, and a model without lights gets the headlight.
  m->vis.global.offwidth = width;
  m->vis.global.offheight = height;
  if (m->nlight == 0) {  // a brighter headlight than MuJoCo's default, which leaves a model without lights dim
    m->vis.headlight.active = 1;
    for (int i = 0; i < 3; ++i) {
      m->vis.headlight.ambient[i] = 0.4f;
      m->vis.headlight.diffuse[i] = 0.6f;
      m->vis.headlight.specular[i] = 0.3f;
    }
  }
  mjvOption option;
  mjv_defaultOption(&option);
  mjvCamera camera = plant_detail::frame_camera(model, frames, option, static_cast<double>(width) / height);
  const EglContext egl;
  Renderer renderer(m, width, height);

  const Clock::time_point render_start = Clock::now();
  std::unique_ptr<Encoder> encoder;
  if (mp4)
    encoder = plant_detail::make_ffmpeg_encoder(ffmpeg, report.file, width, height, options.fps);
  else
    encoder = plant_detail::make_frames_encoder(report.frames_dir, report.file, width, height, options.fps);
  std::vector<unsigned char> rgb;
  const int total = static_cast<int>(frames.size());
  for (int i = 0; i < total; ++i) {
    const FilmFrame& frame = frames[static_cast<std::size_t>(i)];
    const Clock::time_point frame_start = Clock::now();
    plant_detail::pose(model, frame);
    renderer.render(m, model.d, option, camera, time_label(frame.t), rgb);
    report.render_seconds_per_frame += seconds_since(frame_start);
    encoder->add(rgb);
    if (progress) progress(i + 1, total);
  }
  encoder->finish();
  report.frames = total;
  report.seconds_per_frame = seconds_since(render_start) / total;
  report.render_seconds_per_frame /= total;
  report.wall_seconds = seconds_since(start);
  return report;
}

#else  // without MuJoCo

bool film_available() noexcept { return false; }

FilmReport film(const std::string&, const std::vector<FilmFrame>&, const std::filesystem::path&, const FilmOptions&,
                const std::function<void(int, int)>&) {
  throw std::runtime_error(
      "film: redres was built without MuJoCo (install libmujoco-dev, scripts/install_deps.sh, and configure with "
      "REDRES_WITH_MUJOCO=ON)");
}

#endif

}  // namespace redres
