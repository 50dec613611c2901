#pragma once
/// @file
/// The summary of a run as a value: the figures the CLI prints, `compare` tabulates, the golden tests check and
/// summary.json serialises (field by field; docs/output_formats.md). Plugins add their own figures through
/// PluginOutput::summarise(), collected under `metrics`, and their obstacles through PluginOutput::scene_obstacles().

#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "redres/control/plugin.hpp"
#include "redres/model/collision.hpp"
#include "redres/run/plugin_output.hpp"
#include "redres/run/simulation.hpp"

namespace redres {

/// w over the run.
struct ManipulabilityStats {
  double initial = 0.0, final = 0.0, min = 0.0, mean = 0.0, max = 0.0;
};

/// What the solver did over the run.
struct SolverStats {
  std::string engine;            //!< e.g. "projection" or "newton+projection"
  double mean_iterations = 0.0;  //!< per recorded step
  double max_iterations = 0.0;
  double max_residual = 0.0;            //!< largest ||e(u)||_2
  int failures = 0;                     //!< solves that were not `solved`
  std::string first_failure;            //!< "t = ...: <status>: <diagnosis>", or empty
  bool stopped = false;                 //!< the run ended at its first failed step ([solver] on_infeasible = "stop")
  std::string on_infeasible;            //!< the policy: "hold", "stop", "relax" or "brake"
  int held_steps = 0;                   //!< failed steps held with theta_dot = 0
  int relaxed_steps = 0;                //!< steps solved with the rows relaxed ("relax")
  int braked_steps = 0;                 //!< failed steps that braked ("brake", or "relax" where the elastic QP failed)
  double max_relaxed_task_error = 0.0;  //!< the largest max_r |J_r theta_dot - d_r| of a relaxed step
  std::string first_relaxed;            //!< "t = ...: <diagnosis>" of the first relaxed step, or empty
  /// The rows whose solver_status is not 0 (relaxed, braked, held or failed): the task was not met as asked.
  double task_lost_time = 0.0;    //!< their number times tau (s)
  int task_lost_spells = 0;       //!< runs of consecutive such rows
  std::string longest_task_loss;  //!< "t = a s to b s (k steps); back at c s" (or "; not back by the end"), or empty
};

/// A collision shape of a link, in that link's frame (the frames of frames.csv).
struct LinkShapeFacts {
  int joint = 0;    //!< the link's joint, 1-based
  ShapeSpec shape;  //!< with its pose in the link frame resolved (RobotModel::LinkShape::spec)
};

/// Facts about the robot that the plotting tools need.
struct RobotFacts {
  std::string name;
  std::string kind;  //!< "planar" or "spatial"
  std::vector<std::string> joint_names;
  std::vector<std::string> task_rows;  //!< the task's rows, e.g. {"x", "y", "z", "wx", "wy"}
  std::vector<double> lower_limits, upper_limits, link_lengths;
  std::vector<double> base_position;                       //!< the base pose's origin in the world (3)
  std::vector<LinkShapeFacts> link_shapes;                 //!< the links' collision shapes, in joint order
  std::vector<VisualSpec> visuals;                         //!< a URDF robot's visual elements (the viewer draws them)
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();  //!< the base pose P (the base's visuals ride on it)
};

/// The figures one plugin reported.
struct PluginMetrics {
  std::string plugin;           //!< instance name
  std::vector<Metric> metrics;  //!< its named figures
};

/// One obstacle of the scene, for drawing: a world-frame shape at t = 0 (with its velocity if it moves), and the
/// plugin that reported it (PluginOutput::scene_obstacles).
struct ObstacleFacts {
  std::string plugin;  //!< instance name
  ShapeSpec shape;     //!< as configured
};

/// The summary of one run.
struct RunSummary {
  std::string name;                           //!< scenario name
  std::string label;                          //!< the run's name in legends and tables (default: name)
  std::string source;                         //!< scenario file
  std::string status;                         //!< "complete", "stopped" (at a failed step) or "interrupted"
  int steps = 0;                              //!< control steps N (N + 1 rows)
  double tau = 0.0;                           //!< step (s)
  double duration = 0.0;                      //!< T (s)
  std::string integrator;                     //!< "euler" or "heun"
  std::string path;                           //!< the path's description
  double max_position_error = 0.0;            //!< max |r_d - f| over the position rows (m)
  double final_position_error = 0.0;          //!< at t = T (m)
  double max_task_error = 0.0;                //!< the bound on max_position_error ([solver] max_task_error, m)
  bool task_error_exceeded = false;           //!< max_position_error > max_task_error: the run is no success
  double initial_joint_velocity_norm = 0.0;   //!< |theta_dot(0)|
  double final_joint_velocity_norm = 0.0;     //!< |theta_dot(T)|
  ManipulabilityStats manipulability;         //!< w = det(JJ')
  double max_joint_angle_violation = 0.0;     //!< how far any theta left its limits (0 when never)
  double max_joint_velocity_violation = 0.0;  //!< how far any theta_dot left its velocity law (0 when never)
  long steps_with_active_bounds = 0;          //!< steps where some theta_dot sits on a merged bound
  /// Per joint, over the applied commands (RunResult's): the largest |acceleration| and |jerk|, and the largest
  /// excursion beyond the robot's acceleration and jerk limits (empty where it gives none), with the steps over.
  std::vector<double> max_joint_acceleration, max_joint_jerk;
  std::vector<double> max_joint_acceleration_violation, max_joint_jerk_violation;
  int steps_over_acceleration_limit = 0, steps_over_jerk_limit = 0;
  std::vector<double> final_theta;  //!< theta(T)
  SolverStats solver;
  double wall_time_s = 0.0;  //!< time spent in the loop (s)
  RobotFacts robot;
  std::vector<PluginMetrics> metrics;    //!< per plugin that reports figures
  std::vector<ObstacleFacts> obstacles;  //!< every active plugin's obstacles, in the scenario's order
  std::string plant_kind = "kinematic";  //!< [plant] kind: the plant's name (run/plants.hpp)
  PlantFacts plant;                      //!< the MuJoCo plant's figures (all empty on the kinematic plant; no mjcf)

  /// A plugin's metric by plugin instance name and metric name, or nullptr.
  [[nodiscard]] const Metric* metric(const std::string& plugin, const std::string& metric_name) const;
};

/// A value of one summary field.
using SummaryValue = std::variant<long, double, bool, std::string, std::vector<double>, std::vector<std::string>>;

/// One field of the summary: its key in summary.json (nested tables joined by '.', e.g. "solver.max_residual"),
/// its JSON type and its meaning (with the unit), and its value in a summary. summary_fields() is the one list of
/// the summary's fields: summary.json, the Python summary dict, the comparison table (comparison.hpp) and the table
/// in docs/output_formats.md (summary_fields_markdown(), checked by a test) all come from it. The three structured
/// parts (robot.link_shapes, metrics, obstacles) have no `get`: to_json writes them from the summary's members.
struct SummaryField {
  std::string_view key;                              //!< e.g. "manipulability.mean"
  std::string_view type;                             //!< e.g. "number", "array of n numbers"
  std::string_view meaning;                          //!< one line, with the unit
  SummaryValue (*get)(const RunSummary&) = nullptr;  //!< the value; nullptr for a structured part
};

/// Every field of the summary, in the order docs/output_formats.md lists them.
[[nodiscard]] const std::vector<SummaryField>& summary_fields();

/// The table of summary_fields() as docs/output_formats.md shows it (key, type, meaning).
[[nodiscard]] std::string summary_fields_markdown();

/// The value of the field `key` of `summary`; std::invalid_argument listing the keys when there is none.
[[nodiscard]] SummaryValue summary_value(const RunSummary& summary, std::string_view key);

/// Summarises a run of `scenario`.
[[nodiscard]] RunSummary summarise(const Scenario& scenario, const RunResult& run);

/// The summary as JSON text (summary.json). Throws std::runtime_error naming the field when a number in it is not
/// finite (JSON has no inf or nan, and a null in its place would pass silently).
[[nodiscard]] std::string to_json(const RunSummary& summary);

}  // namespace redres
