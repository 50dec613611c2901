#pragma once
/// @file
/// The checked start: what `redres validate` and step 0 of `redres run` check of theta(0) before anything else, so
/// that a start no step can leave fails at once with a diagnosis, not after the whole run's failed steps.
///
///   - limits: every joint within its position limits;
///   - collision: no body of the scheme's collision constraints overlaps another at theta(0) (the pair and depth);
///   - singular: the task rows' Jacobian has a smallest singular value >= kSingularTolerance (and w with it), unless
///     [solver] on_infeasible = "relax", whose elastic QP moves the arm out of a singular start;
///   - path: the path starts within [solver] max_task_error of the end effector at theta(0).
///
/// Each problem comes with a suggestion (for a singular start, a nearby configuration that is not).

#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/run/scenario.hpp"

namespace redres {

/// A task Jacobian whose smallest singular value is below this (m/rad for position rows) is singular for the task.
inline constexpr double kSingularTolerance = 1e-6;

/// One problem of a start.
struct StartProblem {
  std::string kind;        //!< "limits", "collision", "singular" or "path"
  std::string message;     //!< what is wrong, with the figures
  std::string suggestion;  //!< what to do about it
};

/// What check_start() found.
struct StartReport {
  std::vector<StartProblem> problems;  //!< empty: the start is fine
  double w = 0.0;                      //!< w(theta(0)) of the robot's manipulability measure det(JJ')
  double sigma_min = 0.0;              //!< the smallest singular value of the task rows' Jacobian
  double path_offset = 0.0;            //!< |r_d(0) - f(theta(0))| over the task's position rows (m)
  double seconds = 0.0;                //!< how long the check took
  [[nodiscard]] bool ok() const noexcept { return problems.empty(); }
  /// Every problem, one per line: "theta(0) <message> (<suggestion>)".
  [[nodiscard]] std::string text() const;
};

/// Checks theta(0) of `s` (s.theta0). Allocates; takes well under a second.
[[nodiscard]] StartReport check_start(const Scenario& s);

/// A start that check_start() refused: what() holds every problem (StartReport::text()).
class StartError : public std::runtime_error {
 public:
  explicit StartError(StartReport report);
  [[nodiscard]] const StartReport& report() const noexcept { return report_; }

 private:
  StartReport report_;
};

/// check_start(), throwing StartError when it finds a problem.
void require_good_start(const Scenario& s);

}  // namespace redres
