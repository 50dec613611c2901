// A film's PNG frames (libpng) and animated GIF (giflib) (film_encoder.hpp).

#if REDRES_HAVE_MUJOCO

#include <gif_lib.h>
#include <png.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include "plant/film_encoder.hpp"
#include "redres/common/output_file.hpp"

namespace redres::plant_detail {

namespace {

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

}  // namespace

std::unique_ptr<Encoder> make_frames_encoder(const std::filesystem::path& frames_dir, const std::filesystem::path& gif,
                                             int width, int height, double fps) {
  return std::make_unique<FramesEncoder>(frames_dir, gif, width, height, fps);
}

}  // namespace redres::plant_detail

#endif  // REDRES_HAVE_MUJOCO
