// The viewer in a real browser (docs/viewer.md, "Testing the page"): Debian's Chromium, headless, opens view.html
// from the disk with the page's test hook (#test&frame=K), and --dump-dom gives back what the page measured in its
// own scene: no console error, WebGL up, the number of bodies drawn, and where each run's end effector is at frame
// K, which must be where trajectory.csv says (1e-6 m). A screenshot must not be blank. Without Chromium (not
// installable here) the tests are skipped and say so; scripts/install_deps.sh installs it.

#include <png.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_util.hpp"
#include "run_tables.hpp"

namespace redres {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string chromium() {
  if (const char* env = std::getenv("REDRES_CHROMIUM"); env != nullptr && *env != '\0') return env;
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"}) {
    if (fs::exists(p)) return p;
  }
  return "";
}

#define REQUIRE_CHROMIUM()                                                                               \
  if (chromium().empty())                                                                                \
  GTEST_SKIP() << "Chromium is not installed (Debian's package chromium, which scripts/install_deps.sh " \
                  "installs; or set REDRES_CHROMIUM)"

std::string run_command(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return out;
  char buf[65536];
  std::size_t got = 0;
  while ((got = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, got);
  pclose(p);
  return out;
}

// Headless Chromium with WebGL in software (SwiftShader), no sandbox (CI runs as root), a fresh profile.
std::string browser(const fs::path& profile, const std::string& args) {
  return "'" + chromium() +
         "' --headless --no-sandbox --disable-gpu-sandbox --disable-dev-shm-usage --enable-unsafe-swiftshader "
         "--no-first-run "
         "--disable-extensions --hide-scrollbars "
         "--window-size=1400,850 --virtual-time-budget=2000 --user-data-dir='" +
         profile.string() + "' " + args;
}

// What the page's test hook wrote into #redres-test, after the page loaded with #test&frame=K.
json page_state(const fs::path& page, int frame) {
  const fs::path profile = scratch("chromium_profile");
  const std::string dom = run_command(
      browser(profile, "--dump-dom 'file://" + page.string() + "#test&frame=" + std::to_string(frame) + "'") +
      " 2>/dev/null");
  fs::remove_all(profile);
  const std::string open = "<pre id=\"redres-test\" hidden=\"\">";
  const std::size_t a = dom.find(open);
  if (a == std::string::npos) return json{{"dump", dom.substr(0, 2000)}};
  const std::size_t b = dom.find("</pre>", a);
  std::string text = dom.substr(a + open.size(), b - a - open.size());
  for (std::size_t p = text.find("&amp;"); p != std::string::npos; p = text.find("&amp;", p + 1))
    text.replace(p, 5, "&");
  return json::parse(text);
}

// Where trajectory.csv puts the end effector at time t (the row with that time).
std::vector<double> recorded_ee(const RunTable& traj, double t) {
  for (const auto& row : traj.rows) {
    if (std::abs(row[traj.col("t")] - t) > 1e-9) continue;
    return {row[traj.col("r_x")], row[traj.col("r_y")], traj.has("r_z") ? row[traj.col("r_z")] : 0.0};
  }
  return {};
}

std::size_t bodies_in(const fs::path& run) {
  const json s = read_summary(run);
  return s["robot"]["link_shapes"].size() + s["obstacles"].size();
}

void expect_end_effectors(const json& state, const std::vector<fs::path>& runs) {
  ASSERT_EQ(state["ee"].size(), runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const RunTable traj = read_run_table(runs[i] / "trajectory.csv");
    const std::vector<double> want = recorded_ee(traj, state["t"].get<double>());
    ASSERT_EQ(want.size(), 3U) << "no row of " << runs[i] << " at t = " << state["t"];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(state["ee"][i][c].get<double>(), want[static_cast<std::size_t>(c)], 1e-6);
  }
}

struct Pixels {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
};
Pixels read_png(const fs::path& file) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  Pixels p;
  if (png_image_begin_read_from_file(&image, file.c_str()) == 0) return p;
  image.format = PNG_FORMAT_RGB;
  p.rgb.resize(PNG_IMAGE_SIZE(image));
  if (png_image_finish_read(&image, nullptr, p.rgb.data(), 0, nullptr) == 0) return {};
  p.width = static_cast<int>(image.width);
  p.height = static_cast<int>(image.height);
  return p;
}

TEST(ViewBrowser, ThePaperRunReplaysWithTheEndEffectorWhereTheRunPutIt) {
  REQUIRE_CHROMIUM();
  const fs::path run = scratch("browser_paper");
  const Cli r = redres("run configs/paper_r_tvcmm.toml --quiet --set duration=8 --view --out '" + run.string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::size_t frames = read_run_table(run / "frames.csv").rows.size();
  for (const int k : {0, 37, static_cast<int>(frames) - 1}) {
    const json state = page_state(run / "view.html", k);
    ASSERT_TRUE(state.contains("errors")) << state.dump();
    EXPECT_TRUE(state["errors"].empty()) << state["errors"].dump();
    EXPECT_TRUE(state["webgl"].get<bool>());
    EXPECT_EQ(state["frame"].get<int>(), k);
    EXPECT_EQ(state["frames"].get<std::size_t>(), frames);
    EXPECT_EQ(state["bodies"].get<std::size_t>(), bodies_in(run));
    EXPECT_GE(state["plots"].get<int>(), 4);  // w, error, angles, velocities (and accelerations)
    expect_end_effectors(state, {run});
  }
  fs::remove_all(run);
}

TEST(ViewBrowser, ThePandaAmongItsObstaclesIsDrawnAndNotBlank) {
  REQUIRE_CHROMIUM();
  const fs::path run = scratch("browser_panda");
  const Cli r = redres("run configs/panda_hulls_table_pole.toml --quiet --view --out '" + run.string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  const json state = page_state(run / "view.html", 50);
  ASSERT_TRUE(state.contains("errors")) << state.dump();
  EXPECT_TRUE(state["errors"].empty()) << state["errors"].dump();
  EXPECT_EQ(state["bodies"].get<std::size_t>(), 12U);   // 10 hulls, a table and a pole
  EXPECT_EQ(state["visuals"].get<std::size_t>(), 11U);  // the maker's visual meshes, link0 to the fingers
  EXPECT_EQ(bodies_in(run), 12U);
  expect_end_effectors(state, {run});
  // The screenshot: the page's size, and a picture (many colours, most of the scene not background).
  const fs::path profile = scratch("chromium_shot"), shot = run / "shot.png";
  (void)run_command(
      browser(profile, "--screenshot='" + shot.string() + "' 'file://" + (run / "view.html").string() + "#frame=50'") +
      " 2>/dev/null");
  fs::remove_all(profile);
  const Pixels px = read_png(shot);
  ASSERT_EQ(px.width, 1400);
  ASSERT_EQ(px.height, 850);
  std::set<unsigned> colours;
  std::size_t scene_not_background = 0, scene_pixels = 0;
  for (int y = 40; y < 800; ++y) {
    for (int x = 0; x < 800; ++x) {  // the 3-D view is the left part
      const unsigned char* c = &px.rgb[3 * (static_cast<std::size_t>(y) * 1400 + static_cast<std::size_t>(x))];
      colours.insert((unsigned{c[0]} << 16) | (unsigned{c[1]} << 8) | c[2]);
      ++scene_pixels;
      if (std::abs(c[0] - 0xf4) + std::abs(c[1] - 0xf5) + std::abs(c[2] - 0xf7) > 24) ++scene_not_background;
    }
  }
  EXPECT_GT(colours.size(), 200U);
  EXPECT_GT(static_cast<double>(scene_not_background) / static_cast<double>(scene_pixels), 0.1);
  fs::remove_all(run);
}

TEST(ViewBrowser, ACompareViewOverlaysItsRuns) {
  REQUIRE_CHROMIUM();
  const fs::path out = scratch("browser_compare");
  const Cli r = redres(
      "compare configs/paper_r_tvcmm.toml configs/paper_r_mvn.toml --quiet --no-plots --view "
      "--set duration=4 --out '" +
      out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.out;
  const json state = page_state(out / "view.html", 20);
  ASSERT_TRUE(state.contains("errors")) << state.dump();
  EXPECT_TRUE(state["errors"].empty()) << state["errors"].dump();
  EXPECT_EQ(state["runs"].get<int>(), 2);
  EXPECT_EQ(state["bodies"].get<std::size_t>(), bodies_in(out / "paper_r_tvcmm") + bodies_in(out / "paper_r_mvn"));
  expect_end_effectors(state, {out / "paper_r_tvcmm", out / "paper_r_mvn"});
  fs::remove_all(out);
}

}  // namespace
}  // namespace redres
