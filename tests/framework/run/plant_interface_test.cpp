// The plant interface (run/plants.hpp, docs/plant.md): a plant written outside the framework, in this one file with
// one registration, is made by name from a scenario's [plant] kind, driven by simulate()'s one loop, and records its
// own columns; the registry names the plants there are.

#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "redres/control/controller.hpp"
#include "redres/run/plants.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// A plant whose joints follow half of every command (Euler's step), and which records how far it has moved.
class HalfSpeedPlant final : public Plant {
 public:
  explicit HalfSpeedPlant(const Scenario& s) : tau_(s.tau), theta_(s.theta0), moved_(0.0) {}
  [[nodiscard]] const Eigen::VectorXd& theta() const override { return theta_; }
  [[nodiscard]] const Eigen::VectorXd* theta_dot() const override { return nullptr; }
  void record(double* values) override { values[0] = moved_; }
  bool advance(const StepOutput& out, double /*t*/, PlantStep& /*step*/, Eigen::VectorXd& applied,
               std::string& /*failure*/) override {
    applied = 0.5 * out.theta_dot;
    theta_ += tau_ * applied;
    moved_ += tau_ * applied.norm();
    return true;
  }

 private:
  double tau_;
  Eigen::VectorXd theta_;
  double moved_;
};

const bool kRegistered = plant_registry().add(
    {"half_speed", "the joints follow half of every command",
     [](const Scenario&) { return std::vector<std::string>{"moved"}; }, nullptr,
     [](const Scenario& s) -> std::unique_ptr<Plant> { return std::make_unique<HalfSpeedPlant>(s); }});

TEST(PlantInterface, APlantOfOneFileIsMadeByNameAndDrivenByTheOneLoop) {
  ASSERT_TRUE(kRegistered);
  const Scenario kinematic = load_scenario(source_path("configs/paper_r_tvcmm.toml"));
  const Scenario half = load_scenario(source_path("configs/paper_r_tvcmm.toml"), {"plant.kind=half_speed"});
  const RunResult a = simulate(kinematic);
  const RunResult b = simulate(half);
  ASSERT_EQ(a.trajectory.size(), b.trajectory.size());
  // Its own column, after every other one; the kinematic plant adds none.
  EXPECT_EQ(b.trajectory.columns().back(), "moved");
  EXPECT_EQ(b.trajectory.width(), a.trajectory.width() + 1);
  EXPECT_EQ(trajectory_width(half), b.trajectory.width());
  EXPECT_EQ(b.trajectory.at(0, "moved"), 0.0);
  EXPECT_GT(b.trajectory.at(b.trajectory.size() - 1, "moved"), 0.0);
  // The first step is the same on both plants; from then on the half-speed arm lags behind the path.
  EXPECT_EQ(a.trajectory.at(0, "theta_dot_1"), b.trajectory.at(0, "theta_dot_1"));
  EXPECT_GT(summarise(half, b).max_position_error, 10.0 * summarise(kinematic, a).max_position_error);
  EXPECT_EQ(summarise(half, b).plant_kind, "half_speed");
  EXPECT_FALSE(b.plant.has_value());  // it reports no figures of its own
}

TEST(PlantInterface, TheRegistryNamesThePlantsAndRefusesASecondOfOneName) {
  EXPECT_NE(plant_registry().find("kinematic"), nullptr);
  EXPECT_NE(plant_registry().find("mujoco"), nullptr);
  EXPECT_EQ(plant_registry().find("gazebo"), nullptr);
  try {
    (void)plant_registry().at("gazebo");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("unknown plant 'gazebo'; the plants are 'kinematic', 'mujoco'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW((void)plant_registry().add(
                   {"kinematic", "again", nullptr, nullptr,
                    [](const Scenario& s) -> std::unique_ptr<Plant> { return std::make_unique<HalfSpeedPlant>(s); }}),
               std::invalid_argument);
}

}  // namespace
}  // namespace redres
