#include "redres/run/trajectory_columns.hpp"

namespace redres {

const std::vector<TrajectoryColumnGroup>& trajectory_column_groups() {
  using C = ColumnCount;
  using V = StepValue;
  static const std::vector<TrajectoryColumnGroup> groups{
      {"t", C::kOne, "s", "time", V::kTime},
      {"theta_", C::kPerJoint, "rad or m", "joint positions at t (m for prismatic joints)", V::kTheta},
      {"theta_dot_", C::kPerJoint, "rad/s or m/s", "the step's solution x = theta_dot", V::kThetaDot},
      {"lo_", C::kPerJoint, "rad/s or m/s",
       "the QP's merged lower bounds lo (eq. 12): the largest of all plugins' lower bounds", V::kMergedLower},
      {"hi_", C::kPerJoint, "rad/s or m/s", "the QP's merged upper bounds hi", V::kMergedUpper},
      {"rd_", C::kPerReference, "m, rad", "desired task coordinates r_d(t), every reference row", V::kDesired},
      {"r_", C::kPerReference, "m, rad", "actual task coordinates f(theta)", V::kActual},
      {"position_error", C::kOne, "m", "Euclidean norm of r_d - f(theta) over the position rows that are task rows",
       V::kPositionError},
      {"orientation_error", C::kIfOrientation, "rad",
       "tasks with orientation rows only: the angle between the desired and the actual orientation: planar "
       "abs(phi_d - phi), spatial the angle of R_d R'; for a spatial subset (e.g. `wx`, `wy`), the norm of those rows "
       "of the rotation vector of R_d R'",
       V::kOrientationError},
      {"manipulability", C::kOne, "", "w = det(J J') at theta", V::kManipulability},
      {"solver_iterations", C::kOne, "", "iterations of the step's solve", V::kIterations},
      {"solver_residual", C::kOne, "",
       "the solve's residual \\|\\|e(u)\\|\\|_2 ([lvi.md](lvi.md)); `inf` for a step whose bounds conflict",
       V::kResidual},
      {"vel_lo_", C::kPerJoint, "rad/s or m/s",
       "the robot's velocity-limit laws at theta, lower (eq. 8; not the merged bound)", V::kLawLower},
      {"vel_hi_", C::kPerJoint, "rad/s or m/s", "the same, upper", V::kLawUpper},
      {"solver_status", C::kOne, "",
       "the step's status as a number: 0 `solved`, 1 `max_iterations`, 2 `infeasible`, 3 `numerical_error`, 5 "
       "`invalid_problem` (the step's QP could not be built: a plugin or a velocity-limit law gave NaN or inf at that "
       "state, e.g. a formula that is NaN in a window; the step moves nothing, theta_dot is 0, and the diagnosis names "
       "the plugin), 6 `relaxed` (`on_infeasible = \"relax\"`: the QP failed and the elastic QP with the equality rows "
       "relaxed was solved; theta_dot is its answer), 7 `braked` (the step failed and decelerated every joint along "
       "the previous command within its acceleration limits; theta_dot is the braking command, and the arm moves with "
       "it), 8 `inaccurate_primal`, 9 `inaccurate_dual`, 10 `inaccurate_complementarity` (the engine stopped, but its "
       "answer failed that check of the certificate behind `solved`, "
       "[engines.md](engines.md#what-solved-guarantees-the-certificate); a failed step). A failed step that did not "
       "brake (every status but 0, 6 and 7) records theta_dot = 0: the arm is held, "
       "never moved by an unconverged iterate (4 `not_run` exists in the status enum, for a solver "
       "result before its first solve; every recorded row has been solved, so a finished run never records it)",
       V::kStatus},
      {"theta_ddot_", C::kPerJoint, "rad/s^2 or m/s^2",
       "the commanded acceleration: (theta_dot - theta_dot_prev) / tau at the velocity level, x at the acceleration "
       "level (where `lo_`, `hi_` and `theta_dot_` are then x's bounds in rad/s^2 and the velocity command)",
       V::kThetaDdot},
      {"acc_lo_", C::kPerJointIfAccelerationLimits, "rad/s^2 or m/s^2",
       "robots with acceleration limits only: the robot's acceleration-limit laws at theta, lower (not scaled)",
       V::kAccelerationLower},
      {"acc_hi_", C::kPerJointIfAccelerationLimits, "rad/s^2 or m/s^2", "the same, upper", V::kAccelerationUpper},
  };
  return groups;
}

std::vector<std::string> standard_trajectory_columns(const RobotModel& robot) {
  std::vector<std::string> cols;
  for (const TrajectoryColumnGroup& g : trajectory_column_groups()) {
    const std::string name(g.name);
    switch (g.count) {
      case ColumnCount::kOne: cols.push_back(name); break;
      case ColumnCount::kPerJoint:
        for (int j = 1; j <= robot.dof(); ++j) cols.push_back(name + std::to_string(j));
        break;
      case ColumnCount::kPerReference:
        for (const auto& row : robot.reference_names()) cols.push_back(name + row);
        break;
      case ColumnCount::kIfOrientation:
        if (robot.has_orientation_rows()) cols.push_back(name);
        break;
      case ColumnCount::kPerJointIfAccelerationLimits:
        if (!robot.has_acceleration_limits()) break;
        for (int j = 1; j <= robot.dof(); ++j) cols.push_back(name + std::to_string(j));
        break;
    }
  }
  return cols;
}

std::string trajectory_columns_markdown() {
  std::string md = "| column(s) | count | unit | meaning |\n|---|---|---|---|\n";
  for (const TrajectoryColumnGroup& g : trajectory_column_groups()) {
    const std::string name(g.name);
    std::string columns, count;
    switch (g.count) {
      case ColumnCount::kOne:
      case ColumnCount::kIfOrientation:
        columns = "`" + name + "`";
        count = "1";
        break;
      case ColumnCount::kPerJoint:
        columns = "`" + name + "1` .. `" + name + "n`";
        count = "n";
        break;
      case ColumnCount::kPerJointIfAccelerationLimits:
        columns = "`" + name + "1` .. `" + name + "n`";
        count = "n or 0";
        break;
      case ColumnCount::kPerReference:
        columns = "`" + name + "<row>`";
        count = "m_ref";
        break;
    }
    const std::string unit = g.unit.empty() ? "-" : std::string(g.unit);
    md += "| " + columns + " | " + count + " | " + unit + " | " + std::string(g.meaning) + " |\n";
  }
  return md;
}

}  // namespace redres
