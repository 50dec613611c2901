#pragma once
// A film's MuJoCo side (private to src/plant/; compiled with MuJoCo, REDRES_HAVE_MUJOCO): the model and its data, a
// frame's pose, the one camera that frames every frame, and MuJoCo's renderer on the current OpenGL context (an
// EGL context, film_egl.hpp).

#include <string>
#include <vector>

#include "plant/mujoco_load.hpp"
#include "redres/plant/film.hpp"

namespace redres::plant_detail {

// The model and its data, freed together. MuJoCo's errors inside a call are exceptions
// (plant_detail::throw_on_mujoco_errors(), set by load_mjcf()).
struct FilmModel {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  FilmModel() = default;
  FilmModel(const FilmModel&) = delete;
  FilmModel& operator=(const FilmModel&) = delete;
  ~FilmModel() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
};

// Loads MJCF text (plant_detail::load_mjcf: through a virtual file); a model MuJoCo refuses is a bad argument.
void load_model(const std::string& xml, FilmModel& model);

// Puts a frame's configuration into the model's data and computes the poses the renderer draws.
void pose(const FilmModel& model, const FilmFrame& frame);

// One free camera for the whole film: it looks at the centre of the box that holds every visible geom (its bounding
// sphere, geom_xpos +- geom_rbound) over all the frames, from the nearest distance at which the box's eight corners
// (and so, the view being convex, the whole box) lie within the vertical and horizontal fields of view, narrowed by
// the margin.
mjvCamera frame_camera(FilmModel& model, const std::vector<FilmFrame>& frames, const mjvOption& option, double aspect);

// MuJoCo's scene and rendering context, on the current OpenGL context.
class Renderer {
 public:
  Renderer(const mjModel* m, int width, int height);
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;
  ~Renderer() { release(); }

  // Renders the current data into `rgb` (width x height x 3, rows top down) with `text` at the top left.
  void render(const mjModel* m, mjData* d, const mjvOption& option, mjvCamera& camera, const std::string& text,
              std::vector<unsigned char>& rgb);

 private:
  void release() noexcept;

  int width_, height_;
  mjvScene scene_;
  mjrContext context_;
  bool made_ = false;
};

}  // namespace redres::plant_detail
