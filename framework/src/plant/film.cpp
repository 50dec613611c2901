// film(): recorded frames of a MuJoCo model rendered offscreen with MuJoCo's renderer on an EGL context of Mesa's
// surfaceless platform, encoded to an MP4 by ffmpeg or to PNG frames (libpng) and a GIF (giflib). With MuJoCo
// (REDRES_HAVE_MUJOCO) this file includes MuJoCo's, EGL's, libpng's and giflib's headers; without it film() throws.

#include "redres/plant/film.hpp"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#if REDRES_HAVE_MUJOCO
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <fcntl.h>
#include <gif_lib.h>
#include <mujoco/mujoco.h>
#include <png.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string_view>

#include <Eigen/Geometry>

#include "plant/mujoco_load.hpp"
#include "redres/common/output_file.hpp"

extern char** environ;
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

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

std::string hex(long value) {
  char text[32];
  std::snprintf(text, sizeof text, "0x%lx", static_cast<unsigned long>(value));
  return text;
}

// ---- MuJoCo: the model, and its errors as exceptions ---------------------------------------------------------------

// MuJoCo's errors inside a call are exceptions (plant_detail::throw_on_mujoco_errors(), set by load_mjcf()).

struct Model {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  Model() = default;
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;
  ~Model() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
};

// Loads MJCF text (plant_detail::load_mjcf: through a virtual file); a model MuJoCo refuses is a bad argument.
void load_model(const std::string& xml, Model& model) {
  try {
    model.m = plant_detail::load_mjcf(xml);
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(std::string("film: ") + e.what());
  }
  model.d = mj_makeData(model.m);
  if (!model.d) throw std::runtime_error("film: MuJoCo cannot make the model's data");
}

// Puts a frame's configuration into the model's data and computes the poses the renderer draws.
void pose(const Model& model, const FilmFrame& frame) {
  for (int i = 0; i < model.m->nq; ++i) model.d->qpos[i] = frame.qpos(i);
  for (int k = 0; k < model.m->nmocap; ++k)
    for (int i = 0; i < 3; ++i) model.d->mocap_pos[3 * k + i] = frame.mocap_pos(i, k);
  mj_kinematics(model.m, model.d);
  mj_comPos(model.m, model.d);
  mj_camlight(model.m, model.d);
}

// ---- The camera ---------------------------------------------------------------------------------------------------

constexpr double kAzimuth = 135.0;    // degrees
constexpr double kElevation = -25.0;  // degrees: looking down
constexpr double kMargin = 1.1;       // the box is fitted into a field of view narrowed by this factor

// One free camera for the whole film: it looks at the centre of the box that holds every visible geom (its bounding
// sphere, geom_xpos +- geom_rbound) over all the frames, from the nearest distance at which the box's eight corners
// (and so, the view being convex, the whole box) lie within the vertical and horizontal fields of view, narrowed by
// the margin.
mjvCamera frame_camera(Model& model, const std::vector<FilmFrame>& frames, const mjvOption& option, double aspect) {
  const mjModel* m = model.m;
  Eigen::AlignedBox3d box;
  for (const FilmFrame& frame : frames) {
    pose(model, frame);
    for (int g = 0; g < m->ngeom; ++g) {
      if (m->geom_type[g] == mjGEOM_PLANE || m->geom_type[g] == mjGEOM_HFIELD) continue;  // unbounded or terrain
      const int group = m->geom_group[g];
      if (group >= 0 && group < mjNGROUP && option.geomgroup[group] == 0) continue;  // not drawn
      if (m->geom_rgba[4 * g + 3] <= 0.0f) continue;                                 // invisible
      const Eigen::Vector3d centre(model.d->geom_xpos + 3 * g);
      const double r = m->geom_rbound[g];
      box.extend(centre - Eigen::Vector3d::Constant(r));
      box.extend(centre + Eigen::Vector3d::Constant(r));
    }
    if (m->ngeom == 0)
      for (int b = 0; b < m->nbody; ++b) box.extend(Eigen::Vector3d(model.d->xpos + 3 * b));
  }
  if (box.isEmpty()) box.extend(Eigen::Vector3d::Zero());
  const Eigen::Vector3d centre = box.center();
  box.extend(centre + Eigen::Vector3d::Constant(0.05));  // a box of at least 10 cm a side
  box.extend(centre - Eigen::Vector3d::Constant(0.05));

  // MuJoCo's free camera: forward, up and right from the azimuth and elevation; it sits at lookat - distance *
  // forward. A corner at p - lookat is in view when its sideways offsets are within depth * tan(half angle), its
  // depth being distance + (p - lookat) . forward.
  const double az = kAzimuth * M_PI / 180.0, el = kElevation * M_PI / 180.0;
  const Eigen::Vector3d forward(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  const Eigen::Vector3d up(-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az), std::cos(el));
  const Eigen::Vector3d right = forward.cross(up);
  const double tan_y = std::tan(0.5 * static_cast<double>(m->vis.global.fovy) * M_PI / 180.0) / kMargin;
  const double tan_x = tan_y * aspect;
  const double size = box.diagonal().norm();
  double distance = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p = box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)) - centre;
    const double ahead = p.dot(forward);
    distance = std::max(
        {distance, std::abs(p.dot(up)) / tan_y - ahead, std::abs(p.dot(right)) / tan_x - ahead, 0.1 * size - ahead});
  }

  mjvCamera camera;
  mjv_defaultCamera(&camera);
  camera.type = mjCAMERA_FREE;
  for (int i = 0; i < 3; ++i) camera.lookat[i] = centre(i);
  camera.distance = distance;
  camera.azimuth = kAzimuth;
  camera.elevation = kElevation;
  // The clipping planes (vis.map.znear and zfar, times stat.extent) must hold the box: the nearest corner is at least
  // 0.1 * size ahead, the farthest at most distance + size.
  const double extent = m->stat.extent > 0 ? m->stat.extent : 1.0;
  model.m->vis.map.znear = std::min(model.m->vis.map.znear, static_cast<float>(0.05 * size / extent));
  model.m->vis.map.zfar = std::max(model.m->vis.map.zfar, static_cast<float>(2.0 * (distance + size) / extent));
  return camera;
}

// ---- EGL: a context of Mesa's surfaceless platform ----------------------------------------------------------------

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

// An OpenGL context with no surface at all (MuJoCo renders into its own framebuffer object), current on this thread
// while the object lives. The default platform needs an X server or a GPU; the surfaceless one renders in software
// (llvmpipe) anywhere Mesa is installed.
class EglContext {
 public:
  EglContext() {
    try {
      open();
    } catch (...) {
      close();
      throw;
    }
  }
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  ~EglContext() { close(); }

 private:
  [[noreturn]] static void fail(const std::string& step) {
    throw std::runtime_error("film: " + step + " (EGL error " + hex(eglGetError()) +
                             "; rendering needs Mesa's EGL: libegl1, libegl-mesa0 and libgl1-mesa-dri)");
  }

  // The surfaceless display, initialised by the first film and never terminated: terminating the last display
  // unloads Mesa's driver with memory it still holds, which LeakSanitizer then reports as lost (and each film would
  // pay the driver's start-up again). A failure is not remembered: the next film tries again.
  static EGLDisplay display() {
    static const EGLDisplay initialised = [] {
      const auto get_platform_display =
          reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
      if (get_platform_display == nullptr) fail("EGL has no eglGetPlatformDisplayEXT (EGL_EXT_platform_base)");
      const EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (d == EGL_NO_DISPLAY) fail("no EGL display on Mesa's surfaceless platform");
      EGLint major = 0, minor = 0;
      if (eglInitialize(d, &major, &minor) != EGL_TRUE) fail("eglInitialize failed on the surfaceless display");
      return d;
    }();
    return initialised;
  }

  void open() {
    display_ = display();
    // No window (MuJoCo draws into its own framebuffer object); desktop OpenGL, whose fixed-function pipeline
    // MuJoCo 2.2 uses; 8-bit colour.
    const EGLint attributes[] = {EGL_SURFACE_TYPE,
                                 EGL_PBUFFER_BIT,
                                 EGL_RENDERABLE_TYPE,
                                 EGL_OPENGL_BIT,
                                 EGL_RED_SIZE,
                                 8,
                                 EGL_GREEN_SIZE,
                                 8,
                                 EGL_BLUE_SIZE,
                                 8,
                                 EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    if (eglChooseConfig(display_, attributes, &config, 1, &configs) != EGL_TRUE || configs < 1)
      fail("no EGL configuration with desktop OpenGL and 8-bit colour");
    if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) fail("eglBindAPI(EGL_OPENGL_API) failed");
    context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, nullptr);
    if (context_ == EGL_NO_CONTEXT) fail("eglCreateContext failed");
    if (eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE)
      fail("eglMakeCurrent without a surface failed (EGL_KHR_surfaceless_context)");
    current_ = true;
  }

  void close() noexcept {
    if (current_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
    current_ = false;
    context_ = EGL_NO_CONTEXT;
  }

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  bool current_ = false;
};

// MuJoCo's scene and rendering context, on the current OpenGL context.
class Renderer {
 public:
  Renderer(const mjModel* m, int width, int height) : width_(width), height_(height) {
    mjv_defaultScene(&scene_);
    mjr_defaultContext(&context_);
    try {
      mjv_makeScene(m, &scene_, std::max(1000, 2 * m->ngeom + 100));
      const int font = height < 400 ? mjFONTSCALE_100 : height < 1000 ? mjFONTSCALE_150 : mjFONTSCALE_200;
      mjr_makeContext(m, &context_, font);
      made_ = true;
      if (context_.offWidth < width || context_.offHeight < height)
        throw std::runtime_error("film: MuJoCo's offscreen buffer is " + std::to_string(context_.offWidth) + "x" +
                                 std::to_string(context_.offHeight) + ", smaller than the " + std::to_string(width) +
                                 "x" + std::to_string(height) + " asked for");
      mjr_setBuffer(mjFB_OFFSCREEN, &context_);
      if (context_.currentBuffer != mjFB_OFFSCREEN)
        throw std::runtime_error("film: MuJoCo's offscreen framebuffer is not available");
    } catch (...) {
      release();
      throw;
    }
  }
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;
  ~Renderer() { release(); }

  // Renders the current data into `rgb` (width x height x 3, rows top down) with `text` at the top left.
  void render(const mjModel* m, mjData* d, const mjvOption& option, mjvCamera& camera, const std::string& text,
              std::vector<unsigned char>& rgb) {
    mjv_updateScene(m, d, &option, nullptr, &camera, mjCAT_ALL, &scene_);
    const mjrRect viewport{0, 0, width_, height_};
    mjr_render(viewport, &scene_, &context_);
    mjr_overlay(mjFONT_NORMAL, mjGRID_TOPLEFT, viewport, text.c_str(), nullptr, &context_);
    const std::size_t row = 3 * static_cast<std::size_t>(width_);
    rgb.resize(row * static_cast<std::size_t>(height_));
    mjr_readPixels(rgb.data(), nullptr, viewport, &context_);
    if (const int error = mjr_getError(); error != 0)
      throw std::runtime_error("film: OpenGL error " + hex(error) + " while rendering");
    // OpenGL's rows run bottom up; images' top down.
    for (int y = 0; y < height_ / 2; ++y)
      std::swap_ranges(rgb.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(y)),
                       rgb.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(y + 1)),
                       rgb.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(height_ - 1 - y)));
  }

 private:
  void release() noexcept {
    if (made_) mjr_freeContext(&context_);  // (only once made: it calls OpenGL, whose functions it loads)
    made_ = false;
    mjv_freeScene(&scene_);
  }

  int width_, height_;
  mjvScene scene_;
  mjrContext context_;
  bool made_ = false;
};

// ---- Encoders -----------------------------------------------------------------------------------------------------

class Encoder {
 public:
  virtual ~Encoder() = default;
  virtual void add(const std::vector<unsigned char>& rgb) = 0;
  virtual void finish() = 0;  // after the last frame; the encoder's files are in place when it returns
};

// The end of a file's text, at most `bytes` of it, from an open descriptor.
std::string tail_of(int fd, long bytes) {
  struct stat st {};
  if (::fstat(fd, &st) != 0) return "";
  const long start = std::max(0L, static_cast<long>(st.st_size) - bytes);
  std::string text(static_cast<std::size_t>(st.st_size - start), '\0');
  const ssize_t got = ::pread(fd, text.data(), text.size(), start);
  text.resize(got > 0 ? static_cast<std::size_t>(got) : 0);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

// The executable `name` in PATH's directories, or empty.
std::filesystem::path find_on_path(const std::string& name) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return {};
  const std::string_view all(path);
  std::size_t begin = 0;
  while (begin <= all.size()) {
    const std::size_t end = std::min(all.find(':', begin), all.size());
    const std::string directory(all.substr(begin, end - begin));
    const std::filesystem::path candidate = std::filesystem::path(directory.empty() ? "." : directory) / name;
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
      return candidate;
    begin = end + 1;
  }
  return {};
}

// ffmpeg, reading raw RGB frames from a socket on its standard input and writing the MP4 itself (`-n`: it never
// overwrites). A socket rather than a pipe: send(MSG_NOSIGNAL) reports an ffmpeg that died as an error instead of
// raising SIGPIPE in the caller's process. Its messages go to an unlinked temporary file, read back on failure.
class FfmpegEncoder final : public Encoder {
 public:
  FfmpegEncoder(const std::filesystem::path& ffmpeg, const std::filesystem::path& output, int width, int height,
                double fps)
      : output_(output) {
    std::string errors = (std::filesystem::temp_directory_path() / "redres_ffmpeg_XXXXXX").string();
    errors_ = ::mkostemp(errors.data(), O_CLOEXEC);
    if (errors_ < 0)
      throw std::runtime_error("film: cannot create a temporary file for ffmpeg's messages: " +
                               std::string(std::strerror(errno)));
    ::unlink(errors.c_str());
    int sockets[2];
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, sockets) != 0) {
      const int error = errno;
      ::close(errors_);
      throw std::runtime_error("film: cannot make a socket for ffmpeg: " + std::string(std::strerror(error)));
    }
    input_ = sockets[0];
    char size[64], rate[64];
    std::snprintf(size, sizeof size, "%dx%d", width, height);
    std::snprintf(rate, sizeof rate, "%.10g", fps);
    // "file:" and an absolute path: a name that starts with '-' or holds a ':' is still a file name to ffmpeg.
    const std::string target = "file:" + std::filesystem::absolute(output).string();
    std::vector<std::string> args = {
        ffmpeg.string(), "-hide_banner", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt",
        "rgb24",         "-s",           size,        "-r",    rate, "-i",       "-",
        "-pix_fmt",      "yuv420p",      "-n",        target};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, sockets[1], STDIN_FILENO);
    posix_spawn_file_actions_adddup2(&actions, errors_, STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, errors_, STDERR_FILENO);
    const int spawned = ::posix_spawn(&pid_, ffmpeg.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(sockets[1]);
    if (spawned != 0) {
      pid_ = -1;
      close_all();
      throw std::runtime_error("film: cannot start " + ffmpeg.string() + ": " + std::strerror(spawned));
    }
  }
  FfmpegEncoder(const FfmpegEncoder&) = delete;
  FfmpegEncoder& operator=(const FfmpegEncoder&) = delete;

  // A film that failed half way: ffmpeg is stopped and its partial MP4 removed.
  ~FfmpegEncoder() override {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      wait();
      std::error_code ignored;
      if (std::filesystem::is_regular_file(std::filesystem::symlink_status(output_, ignored)))
        std::filesystem::remove(output_, ignored);
    }
    close_all();
  }

  void add(const std::vector<unsigned char>& rgb) override {
    const unsigned char* p = rgb.data();
    std::size_t left = rgb.size();
    while (left > 0 && !broken_) {
      const ssize_t sent = ::send(input_, p, left, MSG_NOSIGNAL);
      if (sent < 0) {
        if (errno == EINTR) continue;
        broken_ = true;  // ffmpeg stopped reading: finish() reports its exit status
        break;
      }
      p += sent;
      left -= static_cast<std::size_t>(sent);
    }
    if (broken_) finish();
  }

  void finish() override {
    if (input_ >= 0) ::close(input_);
    input_ = -1;
    const int status = wait();
    pid_ = -1;
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && !broken_) {
      close_all();
      return;
    }
    std::string how = WIFEXITED(status)     ? "exited with status " + std::to_string(WEXITSTATUS(status))
                      : WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                                            : "failed";
    if (broken_ && WIFEXITED(status) && WEXITSTATUS(status) == 0) how = "stopped reading the frames";
    const std::string messages = tail_of(errors_, 2000);
    close_all();
    std::error_code ignored;
    const bool made = std::filesystem::is_regular_file(std::filesystem::symlink_status(output_, ignored));
    if (made) std::filesystem::remove(output_, ignored);
    throw std::runtime_error("film: ffmpeg " + how + " writing " + output_.string() +
                             (messages.empty() ? std::string(" (no messages)") : ":\n" + messages));
  }

 private:
  int wait() {
    int status = 0;
    while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
  }
  void close_all() noexcept {
    if (input_ >= 0) ::close(input_);
    if (errors_ >= 0) ::close(errors_);
    input_ = errors_ = -1;
  }

  std::filesystem::path output_;
  pid_t pid_ = -1;
  int input_ = -1;
  int errors_ = -1;
  bool broken_ = false;
};

// One PNG (libpng's simplified API, which reports errors in the image rather than by longjmp), through a StagedFile.
void write_png(const std::filesystem::path& file, const std::vector<unsigned char>& rgb, int width, int height) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = PNG_FORMAT_RGB;
  png_alloc_size_t size = 0;
  if (png_image_write_to_memory(&image, nullptr, &size, 0, rgb.data(), 0, nullptr) == 0)
    throw std::runtime_error("film: libpng cannot encode " + file.string() + ": " + image.message);
  std::vector<char> bytes(size);
  if (png_image_write_to_memory(&image, bytes.data(), &size, 0, rgb.data(), 0, nullptr) == 0)
    throw std::runtime_error("film: libpng cannot encode " + file.string() + ": " + image.message);
  StagedFile out(file);
  out.write(std::string_view(bytes.data(), size));
  out.finish();
  out.install();
}

// PNG frames in a directory film() creates, and an animated GIF (giflib, a 256-colour palette per frame by median
// cut, looping forever) written through a StagedFile.
class FramesEncoder final : public Encoder {
 public:
  FramesEncoder(const std::filesystem::path& frames_dir, const std::filesystem::path& gif, int width, int height,
                double fps)
      : frames_dir_(frames_dir), gif_file_(gif), width_(width), height_(height) {
    // mkdir refuses anything already there, a symbolic link included: film() never writes into a directory it did
    // not make.
    if (::mkdir(frames_dir.c_str(), 0777) != 0)
      throw std::runtime_error("film: cannot create " + frames_dir.string() + ": " + std::strerror(errno));
    made_dir_ = true;
    try {
      start(fps);
    } catch (...) {
      if (gif_ != nullptr) EGifCloseFile(gif_, nullptr);
      gif_ = nullptr;
      ::rmdir(frames_dir.c_str());
      throw;
    }
  }
  FramesEncoder(const FramesEncoder&) = delete;
  FramesEncoder& operator=(const FramesEncoder&) = delete;

  // A film that failed half way: the frames written and the directory are removed (the GIF's StagedFile removes its
  // temporary).
  ~FramesEncoder() override {
    if (gif_ != nullptr) EGifCloseFile(gif_, nullptr);
    if (done_) return;
    std::error_code ignored;
    for (const std::filesystem::path& f : written_) std::filesystem::remove(f, ignored);
    if (made_dir_) ::rmdir(frames_dir_.c_str());
  }

  void add(const std::vector<unsigned char>& rgb) override {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05d.png", static_cast<int>(written_.size()));
    const std::filesystem::path file = frames_dir_ / name;
    written_.push_back(file);  // before writing: a failure removes whatever it left
    write_png(file, rgb, width_, height_);
    add_gif_frame(rgb);
  }

  void finish() override {
    int error = 0;
    const int closed = EGifCloseFile(gif_, &error);
    gif_ = nullptr;
    if (closed == GIF_ERROR) fail_gif("cannot finish", error);
    gif_file_.finish();
    gif_file_.install();
    done_ = true;
  }

 private:
  // The GIF's header, up to its first frame.
  void start(double fps) {
    int error = 0;
    gif_ = EGifOpen(&gif_file_, &FramesEncoder::output, &error);
    if (gif_ == nullptr) fail_gif("cannot start", error);
    EGifSetGifVersion(gif_, true);  // GIF89a: delays and the loop extension
    if (EGifPutScreenDesc(gif_, width_, height_, 8, 0, nullptr) == GIF_ERROR) fail_gif("cannot write the header of");
    // NETSCAPE2.0: loop forever (a loop count of 0).
    static const char kApplication[] = "NETSCAPE2.0";
    const unsigned char loop[3] = {1, 0, 0};
    if (EGifPutExtensionLeader(gif_, APPLICATION_EXT_FUNC_CODE) == GIF_ERROR ||
        EGifPutExtensionBlock(gif_, 11, kApplication) == GIF_ERROR ||
        EGifPutExtensionBlock(gif_, 3, loop) == GIF_ERROR || EGifPutExtensionTrailer(gif_) == GIF_ERROR)
      fail_gif("cannot write the loop extension of");
    // A GIF's delays are hundredths of a second; below 2 browsers slow the animation down to 10.
    delay_ = std::max(2, static_cast<int>(std::lround(100.0 / fps)));
  }

  static int output(GifFileType* gif, const GifByteType* bytes, int length) {
    static_cast<StagedFile*>(gif->UserData)
        ->write(std::string_view(reinterpret_cast<const char*>(bytes), static_cast<std::size_t>(length)));
    return length;  // a write error is kept by the StagedFile and reported by its finish()
  }

  [[noreturn]] void fail_gif(const std::string& what, int error = -1) {
    if (error < 0 && gif_ != nullptr) error = gif_->Error;
    const char* text = GifErrorString(error);
    throw std::runtime_error("film: giflib " + what + " " + gif_file_.final_name().string() + ": " +
                             (text ? text : "error " + std::to_string(error)));
  }

  void add_gif_frame(const std::vector<unsigned char>& rgb) {
    const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
    red_.resize(n);
    green_.resize(n);
    blue_.resize(n);
    index_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      red_[i] = rgb[3 * i];
      green_[i] = rgb[3 * i + 1];
      blue_[i] = rgb[3 * i + 2];
    }
    int colours = 256;
    std::vector<GifColorType> palette(256, GifColorType{0, 0, 0});
    if (GifQuantizeBuffer(static_cast<unsigned>(width_), static_cast<unsigned>(height_), &colours, red_.data(),
                          green_.data(), blue_.data(), index_.data(), palette.data()) == GIF_ERROR)
      throw std::runtime_error("film: giflib cannot reduce a frame to 256 colours");
    std::unique_ptr<ColorMapObject, void (*)(ColorMapObject*)> map(GifMakeMapObject(256, palette.data()),
                                                                   GifFreeMapObject);
    if (!map) throw std::runtime_error("film: giflib cannot make a colour map");
    GraphicsControlBlock control{};
    control.DisposalMode = DISPOSE_DO_NOT;
    control.UserInputFlag = false;
    control.DelayTime = delay_;
    control.TransparentColor = NO_TRANSPARENT_COLOR;
    GifByteType extension[4];
    const std::size_t length = EGifGCBToExtension(&control, extension);
    if (EGifPutExtension(gif_, GRAPHICS_EXT_FUNC_CODE, static_cast<int>(length), extension) == GIF_ERROR ||
        EGifPutImageDesc(gif_, 0, 0, width_, height_, false, map.get()) == GIF_ERROR)
      fail_gif("cannot write a frame of");
    for (int y = 0; y < height_; ++y)
      if (EGifPutLine(gif_, index_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width_), width_) ==
          GIF_ERROR)
        fail_gif("cannot write a frame of");
  }

  std::filesystem::path frames_dir_;
  StagedFile gif_file_;
  int width_, height_;
  GifFileType* gif_ = nullptr;
  int delay_ = 4;
  bool made_dir_ = false;
  bool done_ = false;
  std::vector<std::filesystem::path> written_;
  std::vector<GifByteType> red_, green_, blue_, index_;
};

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
  Model model;
  load_model(mjcf, model);
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
      options.encoder == FilmOptions::Encoder::kAuto ? find_on_path("ffmpeg") : std::filesystem::path();
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
  mjvCamera camera = frame_camera(model, frames, option, static_cast<double>(width) / height);
  const EglContext egl;
  Renderer renderer(m, width, height);

  const Clock::time_point render_start = Clock::now();
  std::unique_ptr<Encoder> encoder;
  if (mp4)
    encoder = std::make_unique<FfmpegEncoder>(ffmpeg, report.file, width, height, options.fps);
  else
    encoder = std::make_unique<FramesEncoder>(report.frames_dir, report.file, width, height, options.fps);
  std::vector<unsigned char> rgb;
  const int total = static_cast<int>(frames.size());
  for (int i = 0; i < total; ++i) {
    const FilmFrame& frame = frames[static_cast<std::size_t>(i)];
    const Clock::time_point frame_start = Clock::now();
    pose(model, frame);
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
