// The MuJoCo plant (docs/plant.md) against the controller it runs with, in the same process:
//   BM_PlantControllerStep   one Controller::step of configs/panda_table_pole_mujoco.toml (the baseline), cycling
//                            through the states of that scenario's MuJoCo run with its measured velocities;
//   BM_PlantAdvance/<act>    one MujocoPlant::advance of the same scenario (one 1 ms MuJoCo step, the table and the
//                            pole in the world) with the velocity servo, the impedance controller or the ideal
//                            velocity source, commands cycling through the run's;
//   BM_PlantRun              the whole 20 s run (20,000 control and MuJoCo steps, and the kinematic run beside it).
// The ratio of BM_PlantAdvance to BM_PlantControllerStep is what the plant adds to each control step.

#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "redres/plant/mujoco_plant.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

struct Recorded {
  std::vector<Eigen::VectorXd> theta, theta_dot, command;
  std::vector<double> t;
};

Recorded record(Scenario& s) {
  const RunResult run = simulate(s);
  Recorded r;
  const int n = s.robot->dof();
  for (std::size_t k = 0; k < run.trajectory.size(); k += 10) {
    Eigen::VectorXd q(n), v(n), c(n);
    for (int j = 0; j < n; ++j) {
      q(j) = run.trajectory.at(k, "theta_" + std::to_string(j + 1));
      v(j) = run.trajectory.at(k, "measured_theta_dot_" + std::to_string(j + 1));
      c(j) = run.trajectory.at(k, "theta_dot_" + std::to_string(j + 1));
    }
    r.theta.push_back(q);
    r.theta_dot.push_back(v);
    r.command.push_back(c);
    r.t.push_back(run.trajectory.at(k, "t"));
  }
  return r;
}

const std::string kScenario = "configs/panda_table_pole_mujoco.toml";

void BM_PlantControllerStep(benchmark::State& state) {
  Scenario s = load_scenario(source_path(kScenario));
  const Recorded r = record(s);
  const auto controller = Controller::from_scenario(s);
  StepOutput out = controller->make_output();
  std::size_t k = 0;
  for (auto _ : state) {
    controller->step(r.theta[k], r.theta_dot[k], r.t[k], out);
    benchmark::DoNotOptimize(out.theta_dot.data());
    k = (k + 1) % r.theta.size();
  }
}
BENCHMARK(BM_PlantControllerStep);

void BM_PlantAdvance(benchmark::State& state) {
  Scenario s = load_scenario(source_path(kScenario));
  const Recorded r = record(s);
  PlantConfig config = s.plant;
  config.actuator = static_cast<PlantActuator>(state.range(0));
  MujocoPlant plant(*s.robot, config, s.tau, scenario_obstacles(s, true), s.theta0);
  std::size_t k = 0;
  double t = 0.0;
  for (auto _ : state) {
    plant.advance(r.command[k], t);
    benchmark::DoNotOptimize(plant.theta().data());
    k = (k + 1) % r.command.size();
    t += s.tau;
  }
  state.SetLabel(config.actuator == PlantActuator::kVelocityServo ? "velocity_servo"
                 : config.actuator == PlantActuator::kImpedance   ? "impedance"
                                                                  : "ideal_velocity");
}
BENCHMARK(BM_PlantAdvance)->DenseRange(0, 2);

void BM_PlantRun(benchmark::State& state) {
  Scenario s = load_scenario(source_path(kScenario));
  RunResult run;
  for (auto _ : state) {
    simulate(s, run);
    benchmark::DoNotOptimize(run.trajectory.size());
  }
}
BENCHMARK(BM_PlantRun)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace redres
