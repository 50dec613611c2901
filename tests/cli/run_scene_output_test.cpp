// What `redres run` writes for drawing a run (docs/output_formats.md): frames.csv (the joint frames, decimated to at
// most 500 rows) and summary.json's `obstacles` and `robot.link_shapes`.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// A CSV file as its header and rows of numbers.
struct Csv {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  [[nodiscard]] std::size_t index(const std::string& name) const {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (columns[c] == name) return c;
    }
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
};

Csv read_csv(const std::filesystem::path& file) {
  Csv csv;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::stringstream header(line);
  for (std::string c; std::getline(header, c, ',');) csv.columns.push_back(c);
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::vector<double> values;
    for (std::string v; std::getline(row, v, ',');) values.push_back(std::stod(v));
    csv.rows.push_back(std::move(values));
  }
  return csv;
}

void expect_vector(const nlohmann::json& got, const std::vector<double>& want, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t k = 0; k < want.size(); ++k)
    EXPECT_NEAR(got[k].get<double>(), want[k], 1e-12) << what << "[" << k << "]";
}

// paper_r_obstacle in steps of 0.05 s (801 rows, more than frames.csv keeps; a shorter R is more than the push-rod
// joints can do), with a second obstacle added by --set: a box turned about z that moves, far from the arm.
TEST(CliSceneOutput, RunWritesFramesAndObstacles) {
  const auto dir = scratch("scene");
  const std::string obstacles =
      "constraints.3.obstacles=[{shape=\"sphere\",radius=0.02,xyz=[0.551,0.492,0.0]},"
      "{shape=\"box\",size=[0.02,0.04,0.06],xyz=[-0.5,-0.4,0.0],rpy=[0.0,0.0,0.5],velocity=[0.01,-0.02,0.0]}]";
  const Cli r = redres("run configs/paper_r_obstacle.toml --out '" + dir.string() +
                       "' --quiet --set step=0.05 --set '" + obstacles + "'");
  ASSERT_EQ(r.code, 0) << r.out;

  // frames.csv: t, 12 columns per joint, the end effector.
  const Csv frames = read_csv(dir / "frames.csv");
  std::vector<std::string> expected = {"t"};
  for (int j = 1; j <= 6; ++j) {
    for (const char* c : {"x", "y", "z", "r11", "r12", "r13", "r21", "r22", "r23", "r31", "r32", "r33"}) {
      expected.push_back("joint_" + std::to_string(j) + "_" + c);
    }
  }
  for (const char* c : {"ee_x", "ee_y", "ee_z"}) expected.emplace_back(c);
  EXPECT_EQ(frames.columns, expected);
  // 801 rows of trajectory.csv -> every 2nd: 401 rows, t = 0, 0.1, ..., 40.
  const Csv traj = read_csv(dir / "trajectory.csv");
  ASSERT_EQ(traj.rows.size(), 801u);
  ASSERT_EQ(frames.rows.size(), 401u);
  EXPECT_LE(frames.rows.size(), 500u);
  const std::size_t ft = frames.index("t"), fx = frames.index("ee_x"), fy = frames.index("ee_y"),
                    fz = frames.index("ee_z");
  const std::size_t tt = traj.index("t"), rx = traj.index("r_x"), ry = traj.index("r_y");
  for (std::size_t k = 0; k < frames.rows.size(); ++k) {
    const auto& row = frames.rows[k];
    ASSERT_EQ(row.size(), expected.size());
    const auto& tr = traj.rows[2 * k];
    EXPECT_DOUBLE_EQ(row[ft], tr[tt]) << "row " << k;
    // The end effector is the recorded task position; a planar arm stays in z = 0.
    EXPECT_NEAR(row[fx], tr[rx], 1e-9) << "row " << k;
    EXPECT_NEAR(row[fy], tr[ry], 1e-9) << "row " << k;
    EXPECT_EQ(row[fz], 0.0) << "row " << k;
  }
  EXPECT_DOUBLE_EQ(frames.rows.back()[ft], 40.0);

  // summary.json: the two obstacles as configured (the box's rotation is Rz(0.5)), and the links' capsules.
  const nlohmann::json s = read_summary(dir);
  ASSERT_EQ(s["obstacles"].size(), 2u) << s["obstacles"].dump(2);
  const nlohmann::json& sphere = s["obstacles"][0];
  EXPECT_EQ(sphere["plugin"], "obstacle_avoidance");
  EXPECT_EQ(sphere["shape"], "sphere");
  EXPECT_DOUBLE_EQ(sphere["radius"].get<double>(), 0.02);
  expect_vector(sphere["position"], {0.551, 0.492, 0.0}, "sphere position");
  for (int a = 0; a < 3; ++a) {
    expect_vector(sphere["rotation"][a], {a == 0 ? 1.0 : 0.0, a == 1 ? 1.0 : 0.0, a == 2 ? 1.0 : 0.0},
                  "sphere rotation row " + std::to_string(a));
  }
  expect_vector(sphere["velocity"], {0.0, 0.0, 0.0}, "sphere velocity");
  EXPECT_FALSE(sphere.contains("size"));
  const nlohmann::json& box = s["obstacles"][1];
  EXPECT_EQ(box["shape"], "box");
  expect_vector(box["size"], {0.02, 0.04, 0.06}, "box size");
  expect_vector(box["position"], {-0.5, -0.4, 0.0}, "box position");
  const double c = std::cos(0.5), sn = std::sin(0.5);
  expect_vector(box["rotation"][0], {c, -sn, 0.0}, "box rotation row 0");
  expect_vector(box["rotation"][1], {sn, c, 0.0}, "box rotation row 1");
  expect_vector(box["rotation"][2], {0.0, 0.0, 1.0}, "box rotation row 2");
  expect_vector(box["velocity"], {0.01, -0.02, 0.0}, "box velocity");
  EXPECT_FALSE(box.contains("radius"));

  const nlohmann::json& links = s["robot"]["link_shapes"];
  ASSERT_EQ(links.size(), 6u) << links.dump(2);
  for (int j = 0; j < 6; ++j) {
    EXPECT_EQ(links[j]["joint"], j + 1);
    EXPECT_EQ(links[j]["shape"], "capsule");
    EXPECT_DOUBLE_EQ(links[j]["radius"].get<double>(), 0.02);
    EXPECT_GT(links[j]["length"].get<double>(), 0.0);
  }
  std::filesystem::remove_all(dir);
}

// A scenario without obstacles: `obstacles` is an empty array, and a short run keeps every row in frames.csv.
TEST(CliSceneOutput, NoObstaclesAndShortRunsKeepEveryRow) {
  const auto dir = scratch("scene_none");
  const Cli r = redres("run configs/planar_4link_circle.toml --out '" + dir.string() +
                       "' --quiet --set duration=1 --set step=0.01");
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json s = read_summary(dir);
  ASSERT_TRUE(s["obstacles"].is_array());
  EXPECT_TRUE(s["obstacles"].empty());
  EXPECT_EQ(read_csv(dir / "frames.csv").rows.size(), 101u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace redres
