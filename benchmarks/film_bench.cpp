// Filming a run (film(), docs/plant.md "Filming a run"): what one 800x600 frame of the Panda costs, rendered offscreen
// by MuJoCo on EGL's surfaceless platform (in software, llvmpipe, on a machine without a GPU), against one
// mj_kinematics of the same model (the cheapest step of a physics run) as the baseline.
//
// BM_FilmFrame: the time is rendering alone per frame (the scene, drawing, reading the pixels back: manual time from
// FilmReport::render_seconds_per_frame); the counter `encoded_s` adds the PNG and GIF encoding (seconds_per_frame),
// `setup_s` is the rest of a film() call (loading the model, framing the camera, EGL and MuJoCo's context), once per
// film. BM_FilmBaselineKinematics: MujocoModel::kinematics of the Panda (qpos, then mj_kinematics).
// (Built only with REDRES_WITH_MUJOCO.)

#include <filesystem>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "redres/common/output_file.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/plant/film.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "test_util.hpp"

namespace {

constexpr int kFramesPerFilm = 8;

const redres::RobotModel& panda() {
  static const redres::RobotModel robot = redres::load_robot(redres::source_path("robots/franka_panda.toml"));
  return robot;
}

void BM_FilmFrame(benchmark::State& state) {
  const std::string xml = redres::mjcf_from_robot(panda());
  std::vector<redres::FilmFrame> frames;
  for (int i = 0; i < kFramesPerFilm; ++i) {
    redres::FilmFrame f;
    f.t = 0.04 * i;
    f.qpos = panda().home();
    f.qpos(0) += 0.1 * i;
    frames.push_back(f);
  }
  redres::FilmOptions options;  // 800 x 600
  options.encoder = redres::FilmOptions::Encoder::kFrames;
  const std::filesystem::path dir = redres::make_private_directory("redres_film_bench_");
  double encoded = 0.0, setup = 0.0;
  int films = 0;
  for (auto _ : state) {
    const std::filesystem::path out = dir / std::to_string(films++);
    std::filesystem::create_directory(out);
    const redres::FilmReport report = redres::film(xml, frames, out, options);
    state.SetIterationTime(report.render_seconds_per_frame);
    encoded += report.seconds_per_frame;
    setup += report.wall_seconds - report.seconds_per_frame * report.frames;
    std::filesystem::remove_all(out);
  }
  std::filesystem::remove_all(dir);
  state.counters["encoded_s"] = encoded / films;
  state.counters["setup_s"] = setup / films;
}

void BM_FilmBaselineKinematics(benchmark::State& state) {
  redres::MujocoModel model = redres::MujocoModel::from_xml(redres::mjcf_from_robot(panda()));
  Eigen::VectorXd q = panda().home();
  for (auto _ : state) {
    q(0) += 1e-9;
    model.kinematics(q);
    benchmark::ClobberMemory();
  }
}

BENCHMARK(BM_FilmFrame)->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FilmBaselineKinematics)->Unit(benchmark::kMicrosecond);

}  // namespace
