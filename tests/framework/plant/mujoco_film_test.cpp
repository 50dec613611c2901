// Filming a run (film(), docs/plant.md "Filming a run"): the Panda's MuJoCo model rendered offscreen on EGL's
// surfaceless platform into PNG frames and a GIF, read back with libpng and giflib: the pictures have the size asked
// for, show something, change with the configuration, and the GIF holds every frame and loops; the camera frames a
// mocap obstacle wherever it goes; nothing that exists is written over; bad frames are refused with their sizes named;
// an ffmpeg found on PATH is fed raw frames and its failure reported with its messages (a stand-in script: the
// machines that run the tests need not have ffmpeg). (Built only with REDRES_WITH_MUJOCO.)

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <gif_lib.h>
#include <gtest/gtest.h>
#include <png.h>

#include "redres/common/output_file.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/plant/film.hpp"
#include "redres/plant/mujoco_model.hpp"

namespace redres {
namespace {

namespace fs = std::filesystem;

constexpr int kWidth = 160;
constexpr int kHeight = 120;

struct Picture {
  int width = 0;
  int height = 0;
  std::vector<unsigned char> rgb;  // rows top down
  [[nodiscard]] const unsigned char* at(int x, int y) const {
    return rgb.data() +
           3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x));
  }
};

Picture read_png(const fs::path& file) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&image, file.c_str()) == 0)
    throw std::runtime_error("cannot read " + file.string() + ": " + image.message);
  image.format = PNG_FORMAT_RGB;
  Picture picture;
  picture.width = static_cast<int>(image.width);
  picture.height = static_cast<int>(image.height);
  picture.rgb.resize(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, picture.rgb.data(), 0, nullptr) == 0)
    throw std::runtime_error("cannot decode " + file.string() + ": " + image.message);
  return picture;
}

std::string read_bytes(const fs::path& file) {
  std::string bytes(fs::file_size(file), '\0');
  std::ifstream in(file, std::ios::binary);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  return bytes;
}

// The pixels of a bright red (a red obstacle under the headlight; the robot's geoms are MuJoCo's grey).
bool red(const unsigned char* p) { return p[0] > 120 && p[1] < 60 && p[2] < 60; }

struct RedPixels {
  int count = 0;
  double mean_x = 0.0;  // the mean column of the red pixels
};
RedPixels red_pixels(const Picture& picture) {
  RedPixels out;
  double sum = 0.0;
  for (int y = 0; y < picture.height; ++y)
    for (int x = 0; x < picture.width; ++x)
      if (red(picture.at(x, y))) {
        ++out.count;
        sum += x;
      }
  if (out.count > 0) out.mean_x = sum / out.count;
  return out;
}

// A directory of the test's own, removed at the end.
class TempDir {
 public:
  TempDir() : path_(make_private_directory("redres_film_test_")) {}
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::vector<std::string> listing(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    names.push_back(fs::relative(entry.path(), dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

const RobotModel& panda() {
  static const RobotModel robot = load_robot("robots/franka_panda.toml");
  return robot;
}

// The Panda's model, with a red mocap box (an obstacle) when asked.
std::string panda_mjcf(bool obstacle) {
  std::string xml = mjcf_from_robot(panda());
  if (obstacle) {
    const std::string end = "</worldbody>";
    const std::size_t at = xml.rfind(end);
    EXPECT_NE(at, std::string::npos);
    xml.insert(at,
               "<body name=\"obstacle\" mocap=\"true\" pos=\"0 0 0\">"
               "<geom type=\"box\" size=\"0.15 0.15 0.15\" rgba=\"1 0 0 1\" contype=\"0\" conaffinity=\"0\"/>"
               "</body>\n");
  }
  return xml;
}

// Frames of the Panda moving from home, joint 1 turning and joint 4 bending.
std::vector<FilmFrame> panda_frames(int count, int nmocap = 0) {
  std::vector<FilmFrame> frames;
  for (int i = 0; i < count; ++i) {
    FilmFrame f;
    f.t = 0.04 * i;
    f.qpos = panda().home();
    f.qpos(0) += 0.4 * i;
    f.qpos(3) += 0.2 * i;
    f.mocap_pos = Eigen::Matrix3Xd::Zero(3, nmocap);
    frames.push_back(f);
  }
  return frames;
}

FilmOptions small_frames() {
  FilmOptions options;
  options.width = kWidth;
  options.height = kHeight;
  options.encoder = FilmOptions::Encoder::kFrames;
  return options;
}

TEST(Film, TimesRunFromZeroToTheEndAtTheFrameRate) {
  const std::vector<double> times = film_times(1.0, 25.0);
  ASSERT_EQ(times.size(), 26u);
  EXPECT_EQ(times.front(), 0.0);
  EXPECT_EQ(times.back(), 1.0);
  for (std::size_t i = 1; i < times.size(); ++i) EXPECT_NEAR(times[i] - times[i - 1], 0.04, 1e-12);
  // An end between two frames is a frame of its own; an end of zero is one frame.
  EXPECT_EQ(film_times(0.1, 25.0), (std::vector<double>{0.0, 0.04, 0.08, 0.1}));
  EXPECT_EQ(film_times(0.0, 25.0), std::vector<double>{0.0});
  EXPECT_EQ(film_times(0.3, 10.0).size(), 4u);
  EXPECT_THROW(static_cast<void>(film_times(-1.0, 25.0)), std::invalid_argument);
  EXPECT_THROW(static_cast<void>(film_times(1.0, 0.0)), std::invalid_argument);
}

TEST(Film, ThePandaFilmsToPngFramesAndALoopingGif) {
  ASSERT_TRUE(film_available());
  const TempDir dir;
  const std::vector<FilmFrame> frames = panda_frames(4);
  std::vector<int> done;
  const FilmReport report = film(panda_mjcf(false), frames, dir.path(), small_frames(), [&](int d, int total) {
    EXPECT_EQ(total, 4);
    done.push_back(d);
  });
  EXPECT_EQ(done, (std::vector<int>{1, 2, 3, 4}));
  EXPECT_EQ(report.format, "gif");
  EXPECT_EQ(report.file, dir.path() / "film.gif");
  EXPECT_EQ(report.frames_dir, dir.path() / "film_frames");
  EXPECT_EQ(report.frames, 4);
  EXPECT_GT(report.seconds_per_frame, 0.0);
  EXPECT_GE(report.wall_seconds, report.seconds_per_frame * 4);
  EXPECT_EQ(listing(dir.path()), (std::vector<std::string>{"film.gif", "film_frames", "film_frames/frame_00000.png",
                                                           "film_frames/frame_00001.png", "film_frames/frame_00002.png",
                                                           "film_frames/frame_00003.png"}));

  std::vector<Picture> pictures;
  for (int i = 0; i < 4; ++i)
    pictures.push_back(read_png(dir.path() / "film_frames" / ("frame_0000" + std::to_string(i) + ".png")));
  for (const Picture& p : pictures) {
    EXPECT_EQ(p.width, kWidth);
    EXPECT_EQ(p.height, kHeight);
    // Not one colour: the robot (and the time) is drawn on the background.
    int differing = 0;
    for (int y = 0; y < p.height; ++y)
      for (int x = 0; x < p.width; ++x) differing += std::memcmp(p.at(x, y), p.at(0, 0), 3) != 0;
    EXPECT_GT(differing, kWidth * kHeight / 50);
  }
  // The robot moved between the first and the last frame.
  int changed = 0;
  for (std::size_t i = 0; i < pictures[0].rgb.size(); i += 3)
    changed += std::memcmp(&pictures[0].rgb[i], &pictures[3].rgb[i], 3) != 0;
  EXPECT_GT(changed, kWidth * kHeight / 100);
  // No red in a picture of the grey robot: the obstacle test's red is the obstacle's.
  EXPECT_EQ(red_pixels(pictures[0]).count, 0);

  const std::string gif = read_bytes(report.file);
  ASSERT_GE(gif.size(), 6u);
  EXPECT_EQ(gif.substr(0, 6), "GIF89a");
  EXPECT_NE(gif.find("NETSCAPE2.0"), std::string::npos);  // loops
  int error = 0;
  GifFileType* in = DGifOpenFileName(report.file.c_str(), &error);
  ASSERT_NE(in, nullptr) << GifErrorString(error);
  ASSERT_EQ(DGifSlurp(in), GIF_OK) << GifErrorString(in->Error);
  EXPECT_EQ(in->ImageCount, 4);
  EXPECT_EQ(in->SWidth, kWidth);
  EXPECT_EQ(in->SHeight, kHeight);
  GraphicsControlBlock control;
  ASSERT_EQ(DGifSavedExtensionToGCB(in, 0, &control), GIF_OK);
  EXPECT_EQ(control.DelayTime, 4);  // hundredths of a second at 25 frames per second
  DGifCloseFile(in, &error);
}

TEST(Film, RefusesToWriteOverWhatExists) {
  const TempDir dir;
  const std::vector<FilmFrame> frames = panda_frames(2);
  const std::string xml = panda_mjcf(false);
  static_cast<void>(film(xml, frames, dir.path(), small_frames()));
  const std::vector<std::string> before = listing(dir.path());
  std::vector<FileStamp> stamps;
  for (const std::string& name : before) stamps.push_back(stamp_of(dir.path() / name));
  try {
    static_cast<void>(film(xml, frames, dir.path(), small_frames()));
    FAIL() << "film() wrote into a directory that holds a film";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("exists"), std::string::npos) << e.what();
  }
  EXPECT_EQ(listing(dir.path()), before);
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_EQ(stamp_of(dir.path() / before[i]), stamps[i]) << before[i];

  // A film_frames of someone else's, a directory or a symbolic link to one, is refused before anything is written.
  const TempDir other, target;
  fs::create_directory(other.path() / "film_frames");
  try {
    static_cast<void>(film(xml, frames, other.path(), small_frames()));
    FAIL() << "film() wrote into an existing film_frames";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("film_frames exists"), std::string::npos) << e.what();
  }
  EXPECT_EQ(listing(other.path()), std::vector<std::string>{"film_frames"});
  fs::remove(other.path() / "film_frames");
  fs::create_directory_symlink(target.path(), other.path() / "film_frames");
  EXPECT_THROW(static_cast<void>(film(xml, frames, other.path(), small_frames())), std::runtime_error);
  EXPECT_TRUE(fs::is_empty(target.path()));
  EXPECT_FALSE(fs::exists(other.path() / "film.gif"));
}

TEST(Film, RefusesFramesThatAreNotTheModels) {
  const TempDir dir;
  std::vector<FilmFrame> frames = panda_frames(2);
  frames[1].qpos = Eigen::VectorXd::Zero(3);
  const int nq = MujocoModel::from_xml(panda_mjcf(false)).nq();
  try {
    static_cast<void>(film(panda_mjcf(false), frames, dir.path(), small_frames()));
    FAIL() << "a qpos of the wrong size was filmed";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("frame 1"), std::string::npos) << what;
    EXPECT_NE(what.find("qpos of 3 entries"), std::string::npos) << what;
    EXPECT_NE(what.find("nq is " + std::to_string(nq)), std::string::npos) << what;
  }
  // The model has one mocap body; a frame gives none.
  try {
    static_cast<void>(film(panda_mjcf(true), panda_frames(2), dir.path(), small_frames()));
    FAIL() << "a frame without the obstacle's position was filmed";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("0 mocap positions; the model has 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(static_cast<void>(film(panda_mjcf(false), {}, dir.path(), small_frames())), std::invalid_argument);
  FilmOptions odd = small_frames();
  odd.width = 0;
  EXPECT_THROW(static_cast<void>(film(panda_mjcf(false), panda_frames(1), dir.path(), odd)), std::invalid_argument);
  EXPECT_THROW(static_cast<void>(film("<mujoco><nonsense/></mujoco>", panda_frames(1), dir.path(), small_frames())),
               std::invalid_argument);
  EXPECT_THROW(static_cast<void>(film(panda_mjcf(false), panda_frames(1), dir.path() / "missing", small_frames())),
               std::runtime_error);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

// Without Mesa's driver EGL cannot initialise: film() throws, naming the step and the packages, and writes nothing
// (in a child process: the driver's search path is read when EGL initialises).
TEST(FilmDeathTest, ReportsAnEglThatCannotInitialise) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");  // a fresh process, not a fork of one with Mesa's threads
  const TempDir dir;
  EXPECT_EXIT(
      {
        ::setenv("LIBGL_DRIVERS_PATH", "/nonexistent", 1);
        try {
          static_cast<void>(film(panda_mjcf(false), panda_frames(1), dir.path(), small_frames()));
        } catch (const std::runtime_error& e) {
          const std::string what = e.what();
          std::fprintf(stderr, "%s\n", what.c_str());
          std::exit(what.find("eglInitialize failed") != std::string::npos &&
                            what.find("libegl-mesa0") != std::string::npos && fs::is_empty(dir.path())
                        ? 3
                        : 4);
        }
        std::exit(5);
      },
      ::testing::ExitedWithCode(3), "eglInitialize failed");
}

// The camera frames the robot and the obstacles over the whole run: an obstacle that starts far off to one side and
// ends far off to the other is in the first picture on one side and in the last on the other. (The camera looks from
// azimuth 135 degrees: world +x+y is to the right of the picture.)
TEST(Film, TheCameraFramesAnObstacleFarFromTheRobot) {
  const TempDir dir;
  std::vector<FilmFrame> frames = panda_frames(3, 1);
  frames[0].mocap_pos.col(0) = Eigen::Vector3d(1.5, 1.5, 0.4);
  frames[1].mocap_pos.col(0) = Eigen::Vector3d(0.0, 0.0, 2.0);
  frames[2].mocap_pos.col(0) = Eigen::Vector3d(-1.5, -1.5, 0.4);
  const FilmReport report = film(panda_mjcf(true), frames, dir.path(), small_frames());
  const RedPixels first = red_pixels(read_png(report.frames_dir / "frame_00000.png"));
  const RedPixels last = red_pixels(read_png(report.frames_dir / "frame_00002.png"));
  EXPECT_GT(first.count, 20);
  EXPECT_GT(first.mean_x, 0.6 * kWidth);
  EXPECT_GT(last.count, 20);
  EXPECT_LT(last.mean_x, 0.4 * kWidth);
}

// ffmpeg is looked up on PATH. A stand-in script takes its place: one that stores its standard input (the raw frames)
// in the file named by its last argument, and one that fails with a message.
class FakeFfmpeg {
 public:
  explicit FakeFfmpeg(const std::string& script) {
    const fs::path file = bin_.path() / "ffmpeg";
    std::ofstream(file) << "#!/bin/sh\n" << script;
    fs::permissions(file, fs::perms::owner_all);
    const char* path = std::getenv("PATH");
    if (path) old_path_ = path;
    ::setenv("PATH", (bin_.path().string() + ":" + old_path_.value_or("/usr/bin:/bin")).c_str(), 1);
  }
  FakeFfmpeg(const FakeFfmpeg&) = delete;
  FakeFfmpeg& operator=(const FakeFfmpeg&) = delete;
  ~FakeFfmpeg() {
    if (old_path_)
      ::setenv("PATH", old_path_->c_str(), 1);
    else
      ::unsetenv("PATH");
  }

 private:
  TempDir bin_;
  std::optional<std::string> old_path_;
};

TEST(Film, FeedsFfmpegOnPathRawFramesOfEvenSize) {
  const FakeFfmpeg ffmpeg("for a; do last=$a; done\ncat > \"${last#file:}\"\n");
  const TempDir dir;
  FilmOptions options = small_frames();
  options.encoder = FilmOptions::Encoder::kAuto;
  options.width = kWidth + 1;  // rounded down: yuv420p needs even sides
  const FilmReport report = film(panda_mjcf(false), panda_frames(3), dir.path(), options);
  EXPECT_EQ(report.format, "mp4");
  EXPECT_EQ(report.file, dir.path() / "film.mp4");
  EXPECT_TRUE(report.frames_dir.empty());
  EXPECT_EQ(fs::file_size(report.file), 3u * kWidth * kHeight * 3u);
  EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"film.mp4"});
  // Encoder::kFrames does not use it.
  const TempDir frames_dir;
  EXPECT_EQ(film(panda_mjcf(false), panda_frames(1), frames_dir.path(), small_frames()).format, "gif");
}

TEST(Film, ReportsFfmpegsExitStatusAndMessages) {
  const FakeFfmpeg ffmpeg("cat > /dev/null\necho \"Unknown encoder 'libx264'\" >&2\nexit 3\n");
  const TempDir dir;
  FilmOptions options = small_frames();
  options.encoder = FilmOptions::Encoder::kAuto;
  try {
    static_cast<void>(film(panda_mjcf(false), panda_frames(2), dir.path(), options));
    FAIL() << "a failed ffmpeg went unnoticed";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("ffmpeg exited with status 3"), std::string::npos) << what;
    EXPECT_NE(what.find("Unknown encoder 'libx264'"), std::string::npos) << what;
  }
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
}  // namespace redres
