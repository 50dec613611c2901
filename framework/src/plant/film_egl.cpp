// The EGL context of a film, on Mesa's surfaceless platform (film_egl.hpp).

#if REDRES_HAVE_MUJOCO

#include "plant/film_egl.hpp"

#include <stdexcept>

#include <EGL/eglext.h>

#include "common/text.hpp"

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

namespace redres::plant_detail {

EglContext::EglContext() {
  try {
    open();
  } catch (...) {
    close();
    throw;
  }
}

void EglContext::fail(const std::string& step) {
  throw std::runtime_error("film: " + step + " (EGL error " + hex(eglGetError()) +
                           "; rendering needs Mesa's EGL: libegl1, libegl-mesa0 and libgl1-mesa-dri)");
}

EGLDisplay EglContext::display() {
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

void EglContext::open() {
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

void EglContext::close() noexcept {
  if (current_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
  current_ = false;
  context_ = EGL_NO_CONTEXT;
}

}  // namespace redres::plant_detail

#endif  // REDRES_HAVE_MUJOCO
