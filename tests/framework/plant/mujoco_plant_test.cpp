// The MuJoCo plant in the loop (docs/plant.md, "The plant"): shipped scenarios run on MuJoCo with the controller
// reading the measured state. The nominal Panda helix tracks within 1 mm under the velocity servo; the table-and-pole
// run has no contact with its collision constraints and hits the pole without them; torques never exceed the effort
// limits, and do reach them when the gains ask for more; the ideal velocity source reproduces the kinematic run;
// the generated model carries the actuators, gains, obstacles and drive keys; advance() allocates nothing. (Built
// only with REDRES_WITH_MUJOCO.)

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "alloc_counter.hpp"
#include "redres/config/toml_reader.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/plant/mujoco_model.hpp"
#include "redres/plant/mujoco_plant.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"

namespace redres {
namespace {

struct Ran {
  Scenario scenario;
  RunResult run;
  RunSummary summary;
};

Ran run_config(const std::string& file, const std::vector<std::string>& overrides = {}) {
  Ran r{load_scenario(file, overrides), {}, {}};
  simulate(r.scenario, r.run);
  r.summary = summarise(r.scenario, r.run);
  return r;
}

double column_max(const Trajectory& tr, const std::string& name) {
  double m = 0.0;
  for (std::size_t k = 0; k < tr.size(); ++k) m = std::max(m, std::abs(tr.at(k, name)));
  return m;
}

// No recorded or tracked torque above its joint's effort limit (to rounding).
void expect_within_effort(const Ran& r) {
  ASSERT_TRUE(r.run.plant.has_value());
  const PlantFacts& p = *r.run.plant;
  const int n = r.scenario.robot->dof();
  ASSERT_EQ(p.max_torque.size(), static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    const auto k = static_cast<std::size_t>(j);
    if (!std::isfinite(p.effort_limit[k])) continue;
    EXPECT_LE(p.max_torque[k], p.effort_limit[k] * (1.0 + 1e-9)) << "joint " << j + 1;
    EXPECT_LE(column_max(r.run.trajectory, "torque_" + std::to_string(j + 1)), p.effort_limit[k] * (1.0 + 1e-9));
  }
}

TEST(MujocoPlant, NominalPandaHelixTracksWithinAMillimetreUnderTheVelocityServo) {
  const Ran r =
      run_config("configs/panda_helix.toml", {"plant.kind=mujoco", "plant.kinematic_comparison=true", "step=0.001"});
  ASSERT_TRUE(r.run.plant.has_value());
  EXPECT_EQ(r.run.failures, 0);
  EXPECT_LT(r.summary.max_position_error, 1e-3);
  // The plant is not the kinematic one: its error is the larger, and the arm really moved under MuJoCo.
  EXPECT_GT(r.summary.max_position_error, r.run.plant->kinematic_max_position_error);
  EXPECT_GT(column_max(r.run.trajectory, "measured_theta_dot_1"), 0.0);
  EXPECT_EQ(r.run.plant->actuator, "velocity_servo");
  EXPECT_EQ(r.run.plant->substeps, 1);
  EXPECT_EQ(r.run.plant->mujoco_steps, 20000);
  expect_within_effort(r);
  // The torques hold the arm against gravity: joint 2 and 4 carry most of it.
  EXPECT_GT(r.run.plant->max_torque[3], 5.0);
}

TEST(MujocoPlant, GravityCompensationIsWhatKeepsTheServoOnTheHelix) {
  const Ran r = run_config("configs/panda_helix.toml",
                           {"plant.kind=mujoco", "step=0.001", "plant.gravity_compensation=false", "duration=5"});
  EXPECT_GT(r.summary.max_position_error, 5e-3);  // it sags
}

TEST(MujocoPlant, TableAndPoleHasNoContactWithTheConstraintsAndHitsThePoleWithout) {
  const Ran with = run_config("configs/panda_table_pole_mujoco.toml");
  ASSERT_TRUE(with.run.plant.has_value());
  EXPECT_EQ(with.run.plant->max_contacts, 0);
  EXPECT_TRUE(with.run.plant->contact_pairs.empty());
  EXPECT_EQ(with.run.failures, 0);
  EXPECT_LT(with.summary.max_position_error, 1e-3);
  expect_within_effort(with);

  // constraints.3 is the obstacle avoidance (the table and the pole stay in MuJoCo's world).
  const Ran without = run_config("configs/panda_table_pole_mujoco.toml", {"constraints.3.active=false"});
  ASSERT_TRUE(without.run.plant.has_value());
  EXPECT_GT(without.run.plant->max_contacts, 0);
  ASSERT_FALSE(without.run.plant->contact_pairs.empty());
  const PlantContactPair& first = without.run.plant->contact_pairs.front();
  EXPECT_NE((first.a + first.b).find("obstacle"), std::string::npos) << first.a << " vs " << first.b;
  EXPECT_NE((first.a + first.b).find("panda_"), std::string::npos) << first.a << " vs " << first.b;
  EXPECT_GT(first.first_time, 1.0);
  EXPECT_LT(first.first_time, 20.0);
  EXPECT_GT(without.run.plant->deepest_penetration, 0.0);
  EXPECT_GT(column_max(without.run.trajectory, "contacts"), 0.0);
  expect_within_effort(without);
}

TEST(MujocoPlant, TorquesAreClampedAtTheEffortLimitsWhenTheGainsAskForMore) {
  // A stiff servo on the fast helix without the motion limits asks for more than the Panda's joints give.
  const Ran r = run_config("configs/panda_helix_fast_unlimited_mujoco.toml", {"plant.kv=5000", "duration=1"});
  ASSERT_TRUE(r.run.plant.has_value());
  expect_within_effort(r);
  double ratio = 0.0;
  for (std::size_t j = 0; j < r.run.plant->max_torque.size(); ++j)
    ratio = std::max(ratio, r.run.plant->max_torque[j] / r.run.plant->effort_limit[j]);
  EXPECT_GT(ratio, 0.999);  // some joint reached its limit: the clamp was exercised
  EXPECT_GT(r.run.plant->max_torque_rate[0], 0.0);
}

TEST(MujocoPlant, TheKinematicComparisonRunsOnlyWhenTheScenarioAsksForIt) {
  const Ran without = run_config("configs/paper_r_mujoco.toml", {"plant.kinematic_comparison=false", "duration=4"});
  const Ran with = run_config("configs/paper_r_mujoco.toml", {"duration=4"});
  ASSERT_TRUE(without.run.plant.has_value() && with.run.plant.has_value());
  EXPECT_EQ(without.run.plant->kinematic_max_position_error, 0.0);
  // The comparison is the kinematic run's own figure, and it changes nothing of the MuJoCo run.
  Scenario on_kinematic = load_scenario("configs/paper_r_mujoco.toml", {"duration=4"});
  on_kinematic.plant.kind = "kinematic";
  const RunResult kinematic = simulate(on_kinematic);
  EXPECT_FALSE(kinematic.plant.has_value());
  EXPECT_EQ(with.run.plant->kinematic_max_position_error, summarise(on_kinematic, kinematic).max_position_error);
  EXPECT_EQ(with.summary.max_position_error, without.summary.max_position_error);
  EXPECT_EQ(with.run.trajectory.size(), without.run.trajectory.size());
}

TEST(MujocoPlant, TheIdealVelocitySourceReproducesTheKinematicRun) {
  const Ran r = run_config("configs/panda_helix.toml",
                           {"plant.kind=mujoco", "plant.kinematic_comparison=true", "plant.actuator=ideal_velocity"});
  ASSERT_TRUE(r.run.plant.has_value());
  EXPECT_EQ(r.run.plant->substeps, 10);  // 10 ms control period, 1 ms MuJoCo steps
  // Euler at 1 ms inside each 10 ms period moves exactly as theta += tau theta_dot.
  EXPECT_NEAR(r.summary.max_position_error, r.run.plant->kinematic_max_position_error, 1e-9);
  // The torques are those the motion takes: gravity's, at least, on joint 4.
  EXPECT_GT(r.run.plant->max_torque[3], 5.0);
}

TEST(MujocoPlant, TheControllerReadsTheStateOfDelayAgo) {
  // An ideal velocity source moves exactly with the commands, so the measured angles are known: those of three
  // MuJoCo steps ago with delay = 3 ms.
  const RobotModel robot = load_robot("robots/franka_panda.toml");
  PlantConfig config;
  config.kind = "mujoco";
  config.actuator = PlantActuator::kIdealVelocity;
  config.delay = 0.003;
  MujocoPlant plant(robot, config, 0.001, {}, robot.home());
  std::vector<Eigen::VectorXd> actual{robot.home()};
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd command = Eigen::VectorXd::LinSpaced(7, 0.01 * (k + 1), -0.02 * k);
    plant.advance(command, 0.001 * k);
    actual.push_back(actual.back() + 0.001 * command);
    const std::size_t seen = actual.size() > 4 ? actual.size() - 4 : 0;
    EXPECT_LT((plant.theta() - actual[seen]).cwiseAbs().maxCoeff(), 1e-15) << "after " << k + 1 << " steps";
    if (k >= 3) {
      EXPECT_GT((plant.theta() - actual.back()).cwiseAbs().maxCoeff(), 1e-6);
    }
  }
  // And the controller on a delayed measurement still tracks the nominal helix, a little worse.
  const Ran late = run_config("configs/panda_helix.toml", {"plant.kind=mujoco", "step=0.001", "plant.delay=0.002"});
  EXPECT_EQ(late.run.plant->delay, 0.002);
  EXPECT_LT(late.summary.max_position_error, 2e-3);
}

TEST(MujocoPlant, ThePaperArmWritesItsLetterOnTheMujocoPlant) {
  const Ran r = run_config("configs/paper_r_mujoco.toml");
  ASSERT_TRUE(r.run.plant.has_value());
  EXPECT_EQ(r.run.plant->substeps, 10);
  EXPECT_EQ(r.run.failures, 0);
  EXPECT_LT(r.summary.max_position_error, 1e-3);
  EXPECT_EQ(r.run.plant->max_contacts, 0);
  // The summary carries the plant's figures.
  EXPECT_EQ(std::get<std::string>(summary_value(r.summary, "plant.kind")), "mujoco");
  EXPECT_GT(std::get<double>(summary_value(r.summary, "plant.mujoco_step_us")), 0.0);
}

TEST(MujocoPlant, ARunThatMujocoCannotSimulateStopsWithTheDiagnosisAndKeepsItsRows) {
  // An explicit integrator with a servo far too stiff for the links' inertia, and no effort limit to bound it (the
  // push-rod arm): MuJoCo's state blows up in the first control period.
  Scenario s = load_scenario("configs/paper_r_mujoco.toml", {"plant.integrator=euler", "plant.kv=1e6"});
  const RunResult run = simulate(s);
  EXPECT_TRUE(run.stopped);
  EXPECT_GE(run.failures, 1);
  EXPECT_NE(run.first_failure.find("MuJoCo plant: MuJoCo's simulation"), std::string::npos) << run.first_failure;
  EXPECT_NE(run.first_failure.find("timestep"), std::string::npos) << run.first_failure;
  EXPECT_GT(run.trajectory.size(), 1U);  // the rows up to there are kept
  EXPECT_LT(run.trajectory.size(), 4001U);
  EXPECT_EQ(summarise(s, run).status, "stopped");
}

TEST(MujocoPlant, TheModelCarriesActuatorsGainsObstaclesAndDriveKeys) {
  const Scenario s = load_scenario("configs/panda_table_pole_mujoco.toml", {"plant.kv=[1,2,3,4,5,6,7]"});
  const std::string xml = scenario_mjcf(s);
  EXPECT_NE(xml.find("gainprm=\"7\" biasprm=\"0 0 -7\""), std::string::npos);
  EXPECT_NE(xml.find("forcerange=\"-12 12\""), std::string::npos);
  EXPECT_NE(xml.find("integrator=\"implicit\""), std::string::npos);
  EXPECT_NE(xml.find("timestep=\"0.001\""), std::string::npos);
  const MujocoModel mj = MujocoModel::from_xml(xml);
  EXPECT_GE(mj.geom("obstacle0"), 0);
  EXPECT_GE(mj.geom("obstacle1"), 0);

  const Scenario imp = load_scenario("configs/panda_table_pole_mujoco.toml",
                                     {"plant.actuator=impedance", "plant.kp=600", "plant.kd=[50,50,50,50,30,25,15]"});
  EXPECT_NE(scenario_mjcf(imp).find("gainprm=\"1\" biasprm=\"0 -600 -15\""), std::string::npos);
  const Scenario ideal = load_scenario("configs/panda_table_pole_mujoco.toml", {"plant.actuator=ideal_velocity"});
  EXPECT_EQ(scenario_mjcf(ideal).find("<actuator>"), std::string::npos);

  // The robot file's damping and armature reach MuJoCo's joints.
  const std::string robot = R"(name = "two"
kind = "spatial"
convention = "dh"
[[joints]]
name = "a"
a = 0.2
d = 0.1
alpha = 0.0
limits = [-3, 3]
velocity_limit = { type = "constant", lower = -1, upper = 1 }
damping = 2.5
armature = 0.25
inertia = { mass = 1.0, com = [-0.1, 0, 0], ixx = 0.01, iyy = 0.01, izz = 0.01 }
[[joints]]
name = "b"
a = 0.2
d = 0.0
alpha = 0.0
limits = [-3, 3]
velocity_limit = { type = "constant", lower = -1, upper = 1 }
inertia = { mass = 0.5, com = [-0.1, 0, 0], ixx = 0.01, iyy = 0.01, izz = 0.01 }
)";
  const RobotModel model = load_robot(TableReader::root(parse_toml_string(robot, "two.toml"), "robot"));
  EXPECT_EQ(model.joint(0).damping.value_or(-1.0), 2.5);
  EXPECT_EQ(model.joint(0).armature.value_or(-1.0), 0.25);
  EXPECT_FALSE(model.joint(1).damping.has_value());
  const std::string two = mjcf_from_robot(model);
  EXPECT_NE(two.find("damping=\"2.5\" armature=\"0.25\""), std::string::npos);
}

TEST(MujocoPlant, MovingObstaclesAreMocapBodiesThatMoveAsTheScenarioSays) {
  PlantConfig config;
  config.kind = "mujoco";
  const RobotModel robot = load_robot("robots/franka_panda.toml");
  ShapeSpec still, moving;
  still.shape = moving.shape = ShapeSpec::Kind::kSphere;
  still.radius = moving.radius = 0.05;
  still.xyz = {1.0, 0.0, 0.0};
  moving.xyz = {0.0, 1.0, 0.5};
  moving.velocity = std::array<double, 3>{0.1, -0.2, 0.0};
  MujocoPlant plant(robot, config, 0.01, {still, moving}, robot.home());
  EXPECT_EQ(plant.substeps(), 10);
  const Eigen::Matrix3Xd at = plant.mocap_positions(2.0);
  ASSERT_EQ(at.cols(), 1);  // the still one is a world geom
  EXPECT_NEAR(at(0, 0), 0.2, 1e-15);
  EXPECT_NEAR(at(1, 0), 0.6, 1e-15);
  EXPECT_NEAR(at(2, 0), 0.5, 1e-15);
}

TEST(MujocoPlant, BadPlantTablesAreRefusedAtTheirKeys) {
  const auto message = [](const std::vector<std::string>& overrides) {
    try {
      (void)load_scenario("configs/panda_table_pole_mujoco.toml", overrides);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({"plant.timestep=0.0003"}).find("whole number of MuJoCo time steps"), std::string::npos);
  EXPECT_NE(message({"plant.timestep=0.0003"}).find("key 'timestep'"), std::string::npos)
      << message({"plant.timestep=0.0003"});
  EXPECT_NE(message({"plant.delay=0.0015"}).find("delay"), std::string::npos);
  EXPECT_NE(message({"plant.kv=[1,2]"}).find("kv"), std::string::npos);
  EXPECT_NE(message({"plant.actuator=torque"}).find("velocity_servo"), std::string::npos);
  EXPECT_NE(message({"plant.kind=kinematic"}).find("only with kind = \"mujoco\""), std::string::npos);
  const std::string unknown = message({"plant.kind=gazebo"});
  EXPECT_NE(unknown.find("unknown plant \"gazebo\"; expected one of \"kinematic\", \"mujoco\""), std::string::npos)
      << unknown;
  // A robot without mass properties: every such link named.
  const std::string iiwa = [] {
    try {
      (void)load_scenario("configs/iiwa_pose_circle.toml", {"plant.kind=mujoco"});
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  }();
  EXPECT_NE(iiwa.find("mass properties"), std::string::npos) << iiwa;
  EXPECT_NE(iiwa.find("(no inertia)"), std::string::npos) << iiwa;
}

TEST(MujocoPlant, AdvanceAllocatesNothing) {
  if (!testing::allocation_counting_available()) {
    GTEST_SKIP() << "AddressSanitizer owns malloc here; the release build runs this check";
  }
  const Scenario s = load_scenario("configs/panda_table_pole_mujoco.toml", {"constraints.3.active=false"});
  for (const PlantActuator a :
       {PlantActuator::kVelocityServo, PlantActuator::kImpedance, PlantActuator::kIdealVelocity}) {
    PlantConfig config = s.plant;
    config.actuator = a;
    config.delay = 0.003;
    MujocoPlant plant(*s.robot, config, 0.002, scenario_obstacles(s, true), s.theta0);
    Eigen::VectorXd command = Eigen::VectorXd::Constant(7, 0.3);
    long count = 0;
    {
      const testing::AllocationCounter counter;
      for (int k = 0; k < 500; ++k) plant.advance(command, 0.002 * k);  // into the pole and the table: contacts
      count = counter.count();
    }
    EXPECT_EQ(count, 0) << "actuator " << static_cast<int>(a);
    EXPECT_EQ(plant.mujoco_steps(), 1000);
  }
}

}  // namespace
}  // namespace redres
