#pragma once
// An OpenGL context for filming, without a window (private to src/plant/; compiled with MuJoCo, REDRES_HAVE_MUJOCO).

#include <string>

#include <EGL/egl.h>

namespace redres::plant_detail {

// An OpenGL context with no surface at all (MuJoCo renders into its own framebuffer object), current on this thread
// while the object lives. The default platform needs an X server or a GPU; the surfaceless one renders in software
// (llvmpipe) anywhere Mesa is installed.
class EglContext {
 public:
  EglContext();
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;
  ~EglContext() { close(); }

 private:
  [[noreturn]] static void fail(const std::string& step);
  // The surfaceless display, initialised by the first film and never terminated: terminating the last display
  // unloads Mesa's driver with memory it still holds, which LeakSanitizer then reports as lost (and each film would
  // pay the driver's start-up again). A failure is not remembered: the next film tries again.
  static EGLDisplay display();
  void open();
  void close() noexcept;

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  bool current_ = false;
};

}  // namespace redres::plant_detail
