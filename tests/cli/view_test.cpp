// `redres view` without a browser (docs/viewer.md): what the page holds (the frames, the end effector's offset that
// puts it where the run recorded it, the hulls' geometry, the decimated series), the file's safety rules (created
// exclusively, a view.html redres did not write is never replaced, nothing through a symbolic link), and the errors
// for what cannot be viewed. tests/cli/view_browser_test.cpp opens the page in Chromium.

#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "redres/parsers/mesh_file.hpp"
#include "redres/run/view.hpp"
#include "run_tables.hpp"

namespace redres {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// One short paper run and one short Panda-with-hulls run, made once for the tests below.
class View : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    paper_ = new fs::path(scratch("view_paper"));
    panda_ = new fs::path(scratch("view_panda"));
    ASSERT_EQ(redres("run configs/paper_r_tvcmm.toml --quiet --set duration=6 --out '" + paper_->string() + "'").code,
              0);
    ASSERT_EQ(redres("run configs/panda_hulls_table_pole.toml --quiet --out '" + panda_->string() + "'").code, 0);
  }
  static void TearDownTestSuite() {
    fs::remove_all(*paper_);
    fs::remove_all(*panda_);
    delete paper_;
    delete panda_;
  }
  static json data_of(const fs::path& dir, const ViewOptions& options = {}) {
    ViewReport report;
    return json::parse(view_data({dir}, options, report));
  }
  static fs::path* paper_;
  static fs::path* panda_;
};
fs::path* View::paper_ = nullptr;
fs::path* View::panda_ = nullptr;

TEST_F(View, TheFramesAreFramesCsvAndTheToolOffsetPutsTheEndEffectorWhereTheRunRecordedIt) {
  for (const fs::path* dir : {paper_, panda_}) {
    const json run = data_of(*dir)["runs"][0];
    const RunTable frames = read_run_table(*dir / "frames.csv");
    const int n = static_cast<int>(run["joint_names"].size());
    ASSERT_EQ(run["frames"]["t"].size(), frames.rows.size());
    const auto& poses = run["frames"]["poses"];
    ASSERT_EQ(poses.size(), frames.rows.size() * static_cast<std::size_t>(7 * n));
    const Eigen::Vector3d tool(run["tool"][0].get<double>(), run["tool"][1].get<double>(),
                               run["tool"][2].get<double>());
    double worst = 0.0;
    for (std::size_t k = 0; k < frames.rows.size(); ++k) {
      const std::size_t o = 7 * (k * static_cast<std::size_t>(n) + static_cast<std::size_t>(n - 1));
      const Eigen::Vector3d p(poses[o].get<double>(), poses[o + 1].get<double>(), poses[o + 2].get<double>());
      const Eigen::Quaterniond q(poses[o + 6].get<double>(), poses[o + 3].get<double>(), poses[o + 4].get<double>(),
                                 poses[o + 5].get<double>());
      const Eigen::Vector3d ee = p + q.normalized() * tool;
      const auto& row = frames.rows[k];
      const Eigen::Vector3d recorded(row[frames.col("ee_x")], row[frames.col("ee_y")], row[frames.col("ee_z")]);
      worst = std::max(worst, (ee - recorded).norm());
    }
    EXPECT_LT(worst, 1e-8) << *dir;
  }
}

TEST_F(View, HullsCarryTheirGeometryAndObstaclesTheirShapes) {
  const json run = data_of(*panda_)["runs"][0];
  ASSERT_EQ(run["link_shapes"].size(), 10U);
  for (const auto& s : run["link_shapes"]) {
    ASSERT_EQ(s["shape"], "convex");
    const std::size_t v = s["vertices"].size() / 3, f = s["faces"].size() / 3;
    EXPECT_GE(v, 4U);
    EXPECT_EQ(f, 2 * v - 4) << "a closed triangulated hull has 2V - 4 faces";
    for (const auto& i : s["faces"]) EXPECT_LT(i.get<std::size_t>(), v);
  }
  ASSERT_EQ(run["obstacles"].size(), 2U);
  EXPECT_EQ(run["obstacles"][0]["shape"], "box");
  EXPECT_EQ(run["obstacles"][1]["shape"], "capsule");
  EXPECT_DOUBLE_EQ(run["safety_distances"]["obstacle_avoidance"].get<double>(), 0.02);
}

std::vector<unsigned char> from_base64(const std::string& text) {
  std::vector<unsigned char> out;
  unsigned acc = 0;
  int bits = 0;
  for (const char c : text) {
    int v = -1;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    if (c >= '0' && c <= '9') v = c - '0' + 52;
    if (c == '+') v = 62;
    if (c == '/') v = 63;
    if (v < 0) continue;  // '=' padding
    acc = (acc << 6) | static_cast<unsigned>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<unsigned char>((acc >> bits) & 0xFF));
    }
  }
  return out;
}

TEST_F(View, TheMakersVisualMeshesAreDrawnEachOnceWithEveryTriangle) {
  const json data = data_of(*panda_);
  const json& run = data["runs"][0];
  ASSERT_EQ(run["visuals"].size(), 11U);     // link0 to link7, the hand and two fingers (one finger mesh, twice)
  EXPECT_EQ(run["visuals"][0]["joint"], 0);  // the base's, in the world
  EXPECT_EQ(data["meshes"].size(), 10U);     // the fingers share theirs
  for (const auto& v : run["visuals"]) {
    const std::string key = v["mesh"];
    ASSERT_TRUE(data["meshes"].contains(key)) << key;
    const json& mesh = data["meshes"][key];
    const DrawMesh read = read_draw_mesh(mesh["file"].get<std::string>(), Eigen::Vector3d::Ones());
    ASSERT_EQ(mesh["parts"].size(), read.parts.size());
    for (std::size_t p = 0; p < read.parts.size(); ++p) {
      const json& part = mesh["parts"][p];
      const std::vector<unsigned char> pos = from_base64(part["positions"]);
      ASSERT_EQ(pos.size(), read.parts[p].positions.size() * sizeof(float));
      EXPECT_EQ(std::memcmp(pos.data(), read.parts[p].positions.data(), pos.size()), 0);
      ASSERT_TRUE(part.contains("indices16"));  // every Panda part has fewer than 65,536 vertices
      const std::vector<unsigned char> idx = from_base64(part["indices16"]);
      ASSERT_EQ(idx.size(), read.parts[p].indices.size() * 2);
      for (std::size_t i = 0; i < read.parts[p].indices.size(); ++i) {
        const unsigned got = idx[2 * i] | (unsigned{idx[2 * i + 1]} << 8);
        ASSERT_EQ(got, read.parts[p].indices[i]) << key << " part " << p << " index " << i;
      }
    }
  }
}

TEST_F(View, PlotsKeepAtMostTheStatedNumberOfRowsAndTheLast) {
  const RunTable traj = read_run_table(*paper_ / "trajectory.csv");
  ASSERT_GT(traj.rows.size(), 100U);
  ViewOptions options;
  options.max_plot_points = 100;
  const json run = data_of(*paper_, options)["runs"][0];
  const auto& t = run["series"]["t"];
  EXPECT_LE(t.size(), 100U);
  EXPECT_GE(t.size(), 50U);
  EXPECT_DOUBLE_EQ(t.back().get<double>(), traj.rows.back()[traj.col("t")]);
  EXPECT_EQ(run["series"]["manipulability"].size(), t.size());
  EXPECT_TRUE(run["series"].contains("theta_dot_6"));
  EXPECT_TRUE(run["series"].contains("vel_hi_6"));
  EXPECT_FALSE(run["series"].contains("solver_iterations"));
}

TEST_F(View, TheCommandWritesOneSelfContainedFileAndReplacesOnlyItsOwn) {
  const Cli first = redres("view '" + paper_->string() + "'");
  ASSERT_EQ(first.code, 0) << first.out;
  const fs::path page = *paper_ / "view.html";
  EXPECT_NE(first.out.find("view: " + page.string()), std::string::npos) << first.out;
  const std::string html = read_text(page);
  EXPECT_NE(html.find("THREE.OrbitControls"), std::string::npos);   // three.js and the controls inlined
  EXPECT_EQ(html.find("<script src"), std::string::npos);           // nothing fetched
  EXPECT_EQ(html.find("http://"), html.find("http://www.w3.org"));  // no address but SVG's namespace (three.js)
  // Its own earlier page is replaced; a user's file of that name is not.
  EXPECT_EQ(redres("view --quiet '" + paper_->string() + "'").code, 0);
  { std::ofstream(page, std::ios::app) << "<!-- my notes -->"; }
  const Cli refused = redres("view '" + paper_->string() + "'");
  EXPECT_EQ(refused.code, 2) << refused.out;
  EXPECT_NE(refused.out.find("exists"), std::string::npos) << refused.out;
  EXPECT_NE(read_text(page).find("my notes"), std::string::npos);
  // --out never writes through a symbolic link, and several runs need it.
  const fs::path link = *paper_ / "link.html", target = *paper_ / "target.html";
  { std::ofstream(target) << "mine"; }
  fs::create_symlink(target, link);
  const Cli through = redres("view '" + paper_->string() + "' --out '" + link.string() + "'");
  EXPECT_EQ(through.code, 2) << through.out;
  EXPECT_EQ(read_text(target), "mine");
  const Cli two = redres("view '" + paper_->string() + "' '" + panda_->string() + "'");
  EXPECT_EQ(two.code, 2) << two.out;
  EXPECT_NE(two.out.find("--out"), std::string::npos) << two.out;
  fs::remove(link);
  fs::remove(target);
  fs::remove(page);
}

TEST_F(View, AComparisonHoldsEveryRun) {
  const fs::path out = scratch("view_two.html");
  const Cli r = redres("view '" + paper_->string() + "' '" + panda_->string() + "' --out '" + out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("(2 runs, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" 18 bodies"), std::string::npos) << r.out;  // 6 capsules + 10 hulls + 2 obstacles
  fs::remove(out);
}

TEST_F(View, WhatCannotBeViewedSaysWhy) {
  // Not a run.
  const fs::path empty = scratch_dir("view_empty");
  Cli r = redres("view '" + empty.string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("not a run's directory"), std::string::npos) << r.out;
  // A run with --record none, and one in HDF5.
  const fs::path none = scratch("view_none"), h5 = scratch("view_h5");
  ASSERT_EQ(redres("run configs/paper_r_tvcmm.toml --quiet --record none --out '" + none.string() + "'").code, 0);
  r = redres("view '" + none.string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--record none"), std::string::npos) << r.out;
  ASSERT_EQ(redres("run configs/paper_r_tvcmm.toml --quiet --format hdf5 --out '" + h5.string() + "'").code, 0);
  r = redres("view '" + h5.string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("trajectory.h5"), std::string::npos) << r.out;
  r = redres("run configs/paper_r_tvcmm.toml --quiet --format hdf5 --view --out '" + h5.string() + "-2'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--format hdf5"), std::string::npos) << r.out;
  // three.js missing: the package is named.
  r = redres_env("REDRES_THREE_DIR=/nonexistent ",
                 "view '" + paper_->string() + "' --out '" + empty.string() + "/v.html'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("libjs-three"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(empty / "v.html"));
  for (const fs::path& d : {empty, none, h5}) fs::remove_all(d);
}

TEST_F(View, ASweepRowIsViewedFromTheRunTheSweepKept) {
  const fs::path dir = scratch_dir("view_sweep");
  std::ofstream(dir / "two.toml") << "scenario = \"" << source_path("configs/paper_r_tvcmm.toml").string()
                                  << "\"\n[[vary]]\nkey = \"objectives.1.p\"\nvalues = [0.0, 1.0]\n"
                                     "[output]\nruns = true\nrecord = \"every=10\"\n";
  const Cli sweep =
      redres("sweep '" + (dir / "two.toml").string() + "' --quiet --out '" + (dir / "out").string() + "'");
  ASSERT_EQ(sweep.code, 0) << sweep.out;
  Cli r = redres("view '" + (dir / "out").string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--row"), std::string::npos) << r.out;
  r = redres("view '" + (dir / "out").string() + "' --row 1");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir / "out" / "runs" / "1" / "view.html"));
  r = redres("view '" + (dir / "out").string() + "' --row 7");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("runs = true"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

TEST_F(View, ATitleCannotEndTheScriptEarly) {
  const fs::path out = scratch("view_title.html");
  const Cli r = redres("view '" + paper_->string() + "' --title '</script><b>x' --out '" + out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string html = read_text(out);
  EXPECT_NE(html.find("<title>&lt;/script&gt;&lt;b&gt;x</title>"), std::string::npos);
  EXPECT_NE(html.find("<\\/script><b>x"), std::string::npos);  // in the data, escaped
  fs::remove(out);
}

}  // namespace
}  // namespace redres
