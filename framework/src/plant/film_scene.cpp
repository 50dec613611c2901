// A film's MuJoCo side: the model, a frame's pose, the camera and the renderer (film_scene.hpp).

#if REDRES_HAVE_MUJOCO

#include "plant/film_scene.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "common/text.hpp"

namespace redres::plant_detail {

namespace {

constexpr double kAzimuth = 135.0;    // degrees
constexpr double kElevation = -25.0;  // degrees: looking down
constexpr double kMargin = 1.1;       // the box is fitted into a field of view narrowed by this factor

}  // namespace

void load_model(const std::string& xml, FilmModel& model) {
  try {
    model.m = plant_detail::load_mjcf(xml);
  } catch (const std::runtime_error& e) {
    throw std::invalid_argument(std::string("film: ") + e.what());
  }
  model.d = mj_makeData(model.m);
  if (!model.d) throw std::runtime_error("film: MuJoCo cannot make the model's data");
}

void pose(const FilmModel& model, const FilmFrame& frame) {
  for (int i = 0; i < model.m->nq; ++i) model.d->qpos[i] = frame.qpos(i);
  for (int k = 0; k < model.m->nmocap; ++k)
    for (int i = 0; i < 3; ++i) model.d->mocap_pos[3 * k + i] = frame.mocap_pos(i, k);
  mj_kinematics(model.m, model.d);
  mj_comPos(model.m, model.d);
  mj_camlight(model.m, model.d);
}

mjvCamera frame_camera(FilmModel& model, const std::vector<FilmFrame>& frames, const mjvOption& option, double aspect) {
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

Renderer::Renderer(const mjModel* m, int width, int height) : width_(width), height_(height) {
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

void Renderer::render(const mjModel* m, mjData* d, const mjvOption& option, mjvCamera& camera, const std::string& text,
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

void Renderer::release() noexcept {
  if (made_) mjr_freeContext(&context_);  // (only once made: it calls OpenGL, whose functions it loads)
  made_ = false;
  mjv_freeScene(&scene_);
}

}  // namespace redres::plant_detail

#endif  // REDRES_HAVE_MUJOCO
