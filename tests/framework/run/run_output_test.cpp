// joint_frames (frames.csv): the rows it keeps and the frames it computes; trajectory.csv read back gives the
// recorded doubles bit for bit.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <tuple>

#include <unistd.h>
#include <sstream>

#include <gtest/gtest.h>

#include "redres/model/kinematics.hpp"
#include "redres/parsers/robot_toml.hpp"
#include "redres/run/run_output.hpp"
#include "redres/run/run_summary.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

// A recorded run of `rows` rows for the Panda: t = k / 100 and theta moving from home.
Trajectory fake_run(const RobotModel& robot, std::size_t rows) {
  std::vector<std::string> columns = {"t"};
  for (int j = 1; j <= robot.dof(); ++j) columns.push_back("theta_" + std::to_string(j));
  Trajectory run(columns, rows);
  for (std::size_t r = 0; r < rows; ++r) {
    double* row = run.append_row();
    row[0] = 0.01 * static_cast<double>(r);
    for (int j = 0; j < robot.dof(); ++j) row[1 + j] = 0.1 * (j + 1) * std::sin(0.01 * static_cast<double>(r));
  }
  return run;
}

TEST(JointFrames, KeepsEveryRowUpToTheLimitThenAFixedStrideAndTheLastRow) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  for (const std::size_t rows : {1u, 2u, 7u, 500u, 501u, 998u, 999u, 1000u, 4001u}) {
    for (const std::size_t max_rows : {2u, 3u, 10u, 500u}) {
      const Trajectory run = fake_run(robot, rows);
      const Trajectory f = joint_frames(robot, run, max_rows);
      const std::string what = std::to_string(rows) + " rows, at most " + std::to_string(max_rows);
      EXPECT_LE(f.size(), max_rows) << what;
      if (rows <= max_rows) {
        EXPECT_EQ(f.size(), rows) << what;
      } else {
        EXPECT_GE(f.size(), (max_rows + 1) / 2) << what;  // the smallest stride, not a coarser one
      }
      ASSERT_GE(f.size(), 1u) << what;
      EXPECT_EQ(f(0, 0), 0.0) << what;
      EXPECT_EQ(f(f.size() - 1, 0), run(rows - 1, 0)) << what;
      // Equal steps between the kept rows, but the last one may come sooner.
      if (f.size() >= 3) {
        const double step = f(1, 0) - f(0, 0);
        for (std::size_t k = 1; k + 1 < f.size(); ++k) EXPECT_NEAR(f(k, 0) - f(k - 1, 0), step, 1e-12) << what;
        EXPECT_LE(f(f.size() - 1, 0) - f(f.size() - 2, 0), step + 1e-12) << what;
      }
    }
  }
}

TEST(JointFrames, AreTheKinematicsOfTheRecordedTheta) {
  const RobotModel robot = load_robot(source_path("robots/franka_panda.toml"));
  const Trajectory run = fake_run(robot, 1201);
  const Trajectory f = joint_frames(robot, run);
  ASSERT_EQ(f.size(), 401u);  // stride ceil(1200 / 499) = 3
  EXPECT_EQ(f.width(), 1u + 12u * 7u + 3u);
  KinematicsData k(robot);
  Eigen::VectorXd theta(robot.dof());
  for (const std::size_t r : {0u, 200u, 400u}) {
    for (int j = 0; j < robot.dof(); ++j) theta(j) = run(3 * r, 1 + static_cast<std::size_t>(j));
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    for (int j = 0; j < robot.dof(); ++j) {
      const std::string J = "joint_" + std::to_string(j + 1);
      const Eigen::Isometry3d& T = k.link_frames[static_cast<std::size_t>(j)];
      EXPECT_EQ(f.at(r, J + "_x"), T.translation().x());
      EXPECT_EQ(f.at(r, J + "_y"), T.translation().y());
      EXPECT_EQ(f.at(r, J + "_z"), T.translation().z());
      EXPECT_EQ(f.at(r, J + "_r12"), T.linear()(0, 1));
      EXPECT_EQ(f.at(r, J + "_r31"), T.linear()(2, 0));
    }
    EXPECT_EQ(f.at(r, "ee_x"), k.ee_pose.translation().x());
    EXPECT_EQ(f.at(r, "ee_z"), k.ee_pose.translation().z());
  }
}

// trajectory.csv holds every recorded double in a form that reads back to the same bits: a real run, plus rows of
// awkward values (signed zero, subnormals, the extremes, infinities, random bit patterns).
TEST(TrajectoryCsv, ReadsBackBitForBit) {
  Scenario s = load_scenario(source_path("configs/paper_r_fast.toml"));
  RunResult run = simulate(s);
  const RunSummary summary = summarise(s, run);
  std::mt19937_64 rng(11);
  const double lim = std::numeric_limits<double>::max();
  const double specials[] = {0.0,
                             -0.0,
                             std::numeric_limits<double>::denorm_min(),
                             -5e-324,
                             2.2250738585072014e-308,
                             lim,
                             -lim,
                             std::numeric_limits<double>::infinity(),
                             -std::numeric_limits<double>::infinity(),
                             0.1,
                             1.0 / 3.0,
                             1e22,
                             123456789012345678.0};
  for (int extra = 0; extra < 50; ++extra) {
    double* row = run.trajectory.append_row();
    for (std::size_t c = 0; c < run.trajectory.width(); ++c) {
      if (extra < 5) {
        row[c] = specials[(c + static_cast<std::size_t>(extra)) % std::size(specials)];
      } else {
        std::uint64_t bits = rng();
        std::memcpy(&row[c], &bits, sizeof(bits));
        if (!std::isfinite(row[c])) row[c] = 1.0;
      }
      // frames.csv is computed from the theta columns: they stay finite.
      const std::string& name = run.trajectory.columns()[c];
      if (name.rfind("theta_", 0) == 0 && name.rfind("theta_dot", 0) != 0 && !std::isfinite(row[c])) row[c] = -0.0;
    }
  }
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "redres_csv_round_trip";
  write_run(*s.robot, run, summary, dir);
  std::ifstream in(dir / "trajectory.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  std::size_t r = 0, checked = 0;
  while (std::getline(in, line)) {
    ASSERT_LT(r, run.trajectory.size());
    std::stringstream cells(line);
    std::string cell;
    std::size_t c = 0;
    while (std::getline(cells, cell, ',')) {
      double v = 0.0;
      if (cell == "inf" || cell == "-inf") {
        v = cell[0] == '-' ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
      } else {
        const auto res = std::from_chars(cell.data(), cell.data() + cell.size(), v);
        ASSERT_EQ(res.ec, std::errc()) << cell;
        ASSERT_EQ(res.ptr, cell.data() + cell.size()) << cell;
      }
      const double want = run.trajectory(r, c);
      ASSERT_EQ(std::memcmp(&v, &want, sizeof(v)), 0) << "row " << r << " column " << c << ": " << cell;
      ++c;
      ++checked;
    }
    ASSERT_EQ(c, run.trajectory.width());
    ++r;
  }
  EXPECT_EQ(r, run.trajectory.size());
  EXPECT_GT(checked, 1000u);
  std::filesystem::remove_all(dir);
}

std::string file_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// The names in a directory that start with a dot (the staging files).
std::vector<std::string> hidden(const std::filesystem::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name[0] == '.' && name != kOutputManifest) out.push_back(name);  // a temporary left behind
  }
  return out;
}

TEST(RunOutput, FilesAreReplacedWholeAndAFailedWriteLeavesTheDirectoryAsItWas) {
  const auto dir = std::filesystem::temp_directory_path() / ("redres_atomic_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  const auto run_of = [](const char* duration) {
    Scenario s = load_scenario(source_path("configs/paper_r_fast.toml"), {std::string("duration=") + duration});
    RunResult run = simulate(s);
    RunSummary summary = summarise(s, run);
    return std::make_tuple(std::move(s), std::move(run), std::move(summary));
  };
  auto [sa, ra, ma] = run_of("0.5");
  write_run(*sa.robot, ra, ma, dir);
  auto [sb, rb, mb] = run_of("1.0");
  write_run(*sb.robot, rb, mb, dir);
  EXPECT_TRUE(hidden(dir).empty());
  EXPECT_NE(file_text(dir / "summary.json").find("\"steps\": 1000"), std::string::npos);
  const std::string trajectory = file_text(dir / "trajectory.csv"), frames = file_text(dir / "frames.csv"),
                    summary = file_text(dir / "summary.json");
  EXPECT_EQ(std::count(trajectory.begin(), trajectory.end(), '\n'), 1002);  // header and 1,001 rows
  // A write that fails half-way (here frames.csv cannot be staged: its name is taken by a directory, which is
  // never replaced) changes nothing else and leaves no temporary.
  std::filesystem::rename(dir / "frames.csv", dir / "frames.keep");
  std::filesystem::create_directory(dir / "frames.csv");
  EXPECT_THROW(write_run(*sa.robot, ra, ma, dir), std::runtime_error);
  std::filesystem::remove(dir / "frames.csv");
  std::filesystem::rename(dir / "frames.keep", dir / "frames.csv");
  EXPECT_TRUE(hidden(dir).empty());
  EXPECT_EQ(file_text(dir / "trajectory.csv"), trajectory);
  EXPECT_EQ(file_text(dir / "frames.csv"), frames);
  EXPECT_EQ(file_text(dir / "summary.json"), summary);
  // A read-only summary from an earlier run is replaced with the rest, not left beside new tables.
  std::filesystem::permissions(dir / "summary.json", std::filesystem::perms::owner_read);
  write_run(*sa.robot, ra, ma, dir);
  EXPECT_NE(file_text(dir / "summary.json").find("\"steps\": 500"), std::string::npos);
  const std::string replaced = file_text(dir / "trajectory.csv");
  EXPECT_EQ(std::count(replaced.begin(), replaced.end(), '\n'), 502);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace redres

namespace redres {
namespace {

// JSON has no inf or nan (nlohmann writes null in their place): summary.json refuses them and names the field.
TEST(SummaryJson, ANonFiniteNumberIsAnErrorNamingItsField) {
  Scenario s = load_scenario(source_path("configs/paper_r_fast.toml"), {"duration=0.1"});
  const RunResult run = simulate(s);
  RunSummary summary = summarise(s, run);
  EXPECT_NO_THROW((void)to_json(summary));
  const auto message = [](const RunSummary& bad) {
    try {
      (void)to_json(bad);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  RunSummary a = summary;
  a.solver.max_residual = std::numeric_limits<double>::infinity();
  EXPECT_NE(message(a).find("summary.json: 'solver.max_residual' is inf, not a finite number"), std::string::npos)
      << message(a);
  RunSummary b = summary;
  b.final_theta[2] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(b).find("'final_theta[2]' is nan"), std::string::npos) << message(b);
}

}  // namespace
}  // namespace redres
