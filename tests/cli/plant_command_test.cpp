// The MuJoCo plant from the command line (docs/plant.md): `redres run` of a MuJoCo scenario prints the plant's line
// and writes its figures into summary.json; --write-mjcf writes the model MuJoCo loads; `validate` names the plant;
// --film and --write-mjcf refuse a kinematic scenario; and a build without MuJoCo refuses a MuJoCo scenario with exit
// code 2, naming the package, and writes nothing.

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "redres/plant/mujoco_model.hpp"

namespace redres {
namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(PlantCommand, AMujocoScenarioRunsOrNamesThePackageToInstall) {
  const std::filesystem::path out = scratch("plant_run");
  const Cli r = redres("run configs/paper_r_mujoco.toml --out '" + out.string() + "' --write-mjcf --set duration=4");
  if (!mujoco_available()) {
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("libmujoco-dev"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(out));
    return;
  }
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("MuJoCo plant (velocity_servo, 10 steps of 0.001 s per control step)"), std::string::npos)
      << r.out;
  const nlohmann::json s = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_EQ(s["plant"]["kind"], "mujoco");
  EXPECT_EQ(s["plant"]["max_torque"].size(), 6U);
  EXPECT_GT(s["plant"]["mujoco_step_us"].get<double>(), 0.0);
  EXPECT_LT(s["plant"]["kinematic_max_position_error"].get<double>(), s["max_position_error"].get<double>());
  // The model written is the one MuJoCo loads, actuators and all.
  const std::string xml = read_text(out / "mujoco_model.xml");
  EXPECT_NE(xml.find("<actuator>"), std::string::npos);
  EXPECT_NO_THROW((void)MujocoModel::from_xml(xml));
  std::filesystem::remove_all(out);
}

TEST(PlantCommand, ValidateNamesThePlant) {
  const Cli r = redres("validate configs/panda_table_pole_mujoco.toml");
  if (!mujoco_available()) {
    EXPECT_EQ(r.code, 2) << r.out;
    return;
  }
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("plant: MuJoCo, velocity_servo with gravity compensation, 1 MuJoCo step of 0.001 s"),
            std::string::npos)
      << r.out;
}

TEST(PlantCommand, FilmAndWriteMjcfRefuseAKinematicScenario) {
  const std::filesystem::path out = scratch("plant_refuse");
  for (const char* flag : {"--film", "--write-mjcf"}) {
    const Cli r = redres("run configs/paper_r_tvcmm.toml --out '" + out.string() + "' " + flag);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("kinematic plant; add --set plant.kind=mujoco"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(out / "summary.json"));
  }
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace redres
