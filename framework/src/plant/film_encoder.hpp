#pragma once
// A film's encoders (private to src/plant/; compiled with MuJoCo, REDRES_HAVE_MUJOCO): each takes the rendered frames,
// RGB rows top down, and writes its files; a film that fails half way removes what its encoder wrote.

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace redres::plant_detail {

class Encoder {
 public:
  virtual ~Encoder() = default;
  virtual void add(const std::vector<unsigned char>& rgb) = 0;
  virtual void finish() = 0;  // after the last frame; the encoder's files are in place when it returns
};

// The executable `name` in PATH's directories, or empty.
std::filesystem::path find_on_path(const std::string& name);

// An MP4 written by `ffmpeg` (film_ffmpeg.cpp).
std::unique_ptr<Encoder> make_ffmpeg_encoder(const std::filesystem::path& ffmpeg, const std::filesystem::path& output,
                                             int width, int height, double fps);

// PNG frames in the directory `frames_dir` (which it creates) and an animated GIF `gif` (film_frames.cpp).
std::unique_ptr<Encoder> make_frames_encoder(const std::filesystem::path& frames_dir, const std::filesystem::path& gif,
                                             int width, int height, double fps);

}  // namespace redres::plant_detail
