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
#include "test_util.hpp"

namespace redres {
namespace {

TEST(PlantCommand, AMujocoScenarioRunsOrNamesThePackageToInstall) {
  const std::filesystem::path out = scratch("plant_run");
  const Cli r = redres("run configs/paper_r_mujoco.toml --out '" + out.string() + "' --write-mjcf");
  if (!mujoco_available()) {
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("libmujoco-dev"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(out));
    return;
  }
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("MuJoCo plant (velocity_servo, 10 steps of 0.001 s per control step)"), std::string::npos)
      << r.out;
  const nlohmann::json s = read_summary(out);
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

TEST(PlantCommand, FilmRendersTheRunAfterIt) {
  if (!mujoco_available()) GTEST_SKIP() << "no MuJoCo in this build: AMujocoScenarioRunsOrNamesThePackageToInstall";
  const std::filesystem::path out = scratch("plant_film");
  // PATH without ffmpeg: PNG frames and a GIF, 40 s at 0.5 frames per second: 21 frames.
  const Cli r = redres_env("PATH=/nonexistent ",
                           "run configs/paper_r_mujoco.toml --out '" + out.string() + "' --film --film-fps 0.5");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("film: " + (out / "film.gif").string() + " (21 frames at 0.5 per second"), std::string::npos)
      << r.out;
  EXPECT_TRUE(std::filesystem::is_regular_file(out / "film_frames" / "frame_00020.png"));
  EXPECT_FALSE(std::filesystem::exists(out / "film_frames" / "frame_00021.png"));
  EXPECT_EQ(read_text(out / "film.gif").substr(0, 6), "GIF89a");
  // Again into the same directory: refused before the run (exit code 2), the first film untouched.
  const auto stamp = std::filesystem::last_write_time(out / "summary.json");
  const Cli again = redres_env("PATH=/nonexistent ",
                               "run configs/paper_r_mujoco.toml --out '" + out.string() + "' --film --film-fps 0.5");
  EXPECT_EQ(again.code, 2) << again.out;
  EXPECT_NE(again.out.find("--film: " + (out / "film.gif").string() + " exists"), std::string::npos) << again.out;
  EXPECT_EQ(std::filesystem::last_write_time(out / "summary.json"), stamp);  // the run did not start
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

TEST(PlantCommand, WriteMjcfReplacesOnlyAModelItWrote) {
  // Issue 43: --write-mjcf replaced a user's own mujoco_model.xml in --out, silently.
  if (!mujoco_available()) GTEST_SKIP() << "no MuJoCo in this build: AMujocoScenarioRunsOrNamesThePackageToInstall";
  const std::filesystem::path out = scratch("plant_mjcf_mine");
  std::filesystem::create_directories(out);
  std::ofstream(out / "mujoco_model.xml") << "<mine/>\n";
  const std::string run = "run configs/paper_r_mujoco.toml --quiet --write-mjcf --out '";
  Cli r = redres(run + out.string() + "'");
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("mujoco_model.xml exists, and redres did not write it there"), std::string::npos) << r.out;
  EXPECT_EQ(read_text(out / "mujoco_model.xml"), "<mine/>\n");
  EXPECT_FALSE(std::filesystem::exists(out / "summary.json"));
  std::filesystem::remove_all(out);
  // Its own model, from an earlier run into the same directory, is replaced.
  const std::filesystem::path again = scratch("plant_mjcf_again");
  for (int k = 0; k < 2; ++k) {
    r = redres(run + again.string() + "'");
    ASSERT_EQ(r.code, 0) << "run " << k << ": " << r.out;
    EXPECT_NE(read_text(again / "mujoco_model.xml").find("<actuator>"), std::string::npos);
  }
  std::filesystem::remove_all(again);
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
