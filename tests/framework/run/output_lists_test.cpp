// One list per output: the standard trajectory columns and the summary's fields are each declared once, and the
// CSV header, summary.json and docs/output_formats.md follow them. The page must hold the tables the lists make
// (the failure message prints the table to paste).

#include <fstream>
#include <iomanip>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "redres/parsers/robot_toml.hpp"
#include "redres/run/comparison.hpp"
#include "redres/run/run_summary.hpp"
#include "redres/run/scenario.hpp"
#include "redres/run/simulation.hpp"
#include "redres/run/trajectory_columns.hpp"
#include "test_util.hpp"

namespace redres {
namespace {

TEST(OutputLists, TheDocsShowTheTablesTheListsMake) {
  const std::string page = read_text(source_path("docs/output_formats.md"));
  const std::string columns = trajectory_columns_markdown();
  EXPECT_NE(page.find(columns), std::string::npos) << "docs/output_formats.md lacks the trajectory table:\n" << columns;
  const std::string fields = summary_fields_markdown();
  EXPECT_NE(page.find(fields), std::string::npos) << "docs/output_formats.md lacks the summary table:\n" << fields;
}

TEST(OutputLists, ARunRecordsTheListedColumnsThenThePlugins) {
  Scenario s = load_scenario(source_path("configs/paper_r_obstacle.toml"), {"duration=0.2"});
  const RunResult run = simulate(s);
  const std::vector<std::string> standard = standard_trajectory_columns(*s.robot);
  ASSERT_EQ(standard.size(), 52U);  // 1 + 7n + 2m + 5 for the paper's arm (n = 6, m = 2)
  const auto& recorded = run.trajectory.columns();
  ASSERT_GT(recorded.size(), standard.size());
  for (std::size_t c = 0; c < standard.size(); ++c) EXPECT_EQ(recorded[c], standard[c]) << "column " << c;
  EXPECT_EQ(recorded[standard.size()], "min_obstacle_distance");  // the plugin's columns follow
  // Each group's columns hold what it says: spot checks against the run's own values.
  EXPECT_EQ(run.trajectory.at(0, "t"), 0.0);
  for (int j = 0; j < s.robot->dof(); ++j) {
    EXPECT_EQ(run.trajectory.at(0, "theta_" + std::to_string(j + 1)), s.theta0(j));
  }
}

TEST(OutputLists, SummaryJsonHasEveryListedFieldAndNothingElse) {
  Scenario s = load_scenario(source_path("configs/paper_r_obstacle.toml"), {"duration=0.2"});
  const RunResult run = simulate(s);
  const RunSummary summary = summarise(s, run);
  const nlohmann::json j = nlohmann::json::parse(to_json(summary));
  std::size_t leaves = 0;
  for (const SummaryField& f : summary_fields()) {
    std::string pointer = "/" + std::string(f.key);
    for (auto& ch : pointer) ch = ch == '.' ? '/' : ch;
    ASSERT_TRUE(j.contains(nlohmann::json::json_pointer(pointer))) << f.key;
    if (f.get == nullptr) continue;
    ++leaves;
    const nlohmann::json& v = j.at(nlohmann::json::json_pointer(pointer));
    std::visit([&](const auto& want) { EXPECT_EQ(v, nlohmann::json(want)) << f.key; }, f.get(summary));
  }
  // Every scalar or array of the JSON outside the structured parts is a listed field.
  std::size_t json_leaves = 0;
  for (const auto& [key, value] : j.items()) {
    if (key == "metrics" || key == "obstacles") continue;
    if (value.is_object()) {
      for (const auto& [inner, _] : value.items())
        json_leaves += key == "robot" && (inner == "link_shapes" || inner == "visuals") ? 0 : 1;
    } else {
      ++json_leaves;
    }
  }
  EXPECT_EQ(json_leaves, leaves);
}

TEST(OutputLists, TheLabelNamesTheRunAndDefaultsToTheName) {
  // No `label` in the file: the scenario's name; a `label`: that, in the summary and its JSON; an empty one: an error.
  Scenario plain = load_scenario(source_path("configs/paper_r_fast.toml"), {"duration=0.1"});
  EXPECT_EQ(plain.label, plain.name);
  EXPECT_EQ(summarise(plain, simulate(plain)).label, "paper_r_fast");
  Scenario named = load_scenario(source_path("configs/paper_r_fast.toml"), {"duration=0.1", "label=p = 2, fast"});
  EXPECT_EQ(named.name, "paper_r_fast");
  const RunSummary summary = summarise(named, simulate(named));
  EXPECT_EQ(summary.label, "p = 2, fast");
  EXPECT_EQ(nlohmann::json::parse(to_json(summary))["label"], "p = 2, fast");
  EXPECT_THROW((void)load_scenario(source_path("configs/paper_r_fast.toml"), {"label="}), ConfigError);
}

TEST(OutputLists, TheComparisonShowsTheSummaryFieldsItNames) {
  Scenario s = load_scenario(source_path("configs/paper_r_fast.toml"), {"duration=0.5"});
  const RunSummary summary = summarise(s, simulate(s));
  const std::vector<std::string> cells = comparison_cells(summary);
  ASSERT_EQ(cells.size(), comparison_columns().size());
  EXPECT_EQ(cells[0], summary.name);
  EXPECT_EQ(cells[1], summary.label);
  EXPECT_EQ(cells[2], summary.solver.engine);
  std::ostringstream error;
  error << std::setprecision(4) << summary.max_position_error;  // the column's 4 significant digits
  EXPECT_EQ(cells[3], error.str());
  EXPECT_EQ(comparison_markdown_heading().substr(0, 32), "| scenario | label | engine | ma");
  EXPECT_EQ(comparison_csv_heading(),
            "scenario,label,engine,max_position_error,w_initial,w_final,w_min,w_mean,initial_joint_velocity_norm,"
            "final_joint_velocity_norm,mean_iterations,failures,wall_time_s\n");
  EXPECT_THROW((void)summary_value(summary, "no_such_field"), std::invalid_argument);
}

}  // namespace
}  // namespace redres
