#pragma once
// The baseline's inputs taken from a loaded paper scenario (outside any timed region): the arm's lengths, limits and
// velocity laws, the scheme's constants, theta(0), and the desired path as a table of r_d and r_d_dot per step.
// Shared by the step-loop benchmark and the test that the baseline and the framework compute the same run.

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "paper_baseline.hpp"
#include "redres/constraints/joint_angle_margin.hpp"
#include "redres/constraints/task_tracking.hpp"
#include "redres/objectives/manipulability.hpp"
#include "redres/run/scenario.hpp"
#include "redres/velocity_limits/constant.hpp"
#include "redres/velocity_limits/push_rod.hpp"

namespace redres::baseline {

struct Case {
  PaperArm arm;
  Joints theta0{};
  std::vector<double> r_d, r_d_dot;  // 2 (steps + 1)
  LetterR letter;                    // the same path, for run_letter_r
  int steps = 0;
  double tau = 0.0;
};

template <class P, class List>
const P& find_plugin(const List& list) {
  for (const auto& p : list) {
    if (const auto* q = dynamic_cast<const P*>(p.get())) return *q;
  }
  throw std::invalid_argument("the scenario has no " + std::string(P::kType));
}

/// The case of a TVCMM scenario of the paper's arm (constant law on joint 1, push-rod laws on joints 2..6).
inline Case paper_case(const Scenario& s) {
  const RobotModel& robot = *s.robot;
  if (robot.dof() != kJoints) throw std::invalid_argument("the baseline is the paper's 6-joint arm");
  Case c;
  const auto& margin = find_plugin<JointAngleMargin>(s.scheme->constraints()).settings();
  const auto& task = find_plugin<TaskTracking>(s.scheme->constraints()).settings();
  const auto& manip = find_plugin<Manipulability>(s.scheme->objectives()).settings();
  c.arm.kappa = margin.kappa;
  c.arm.gain = task.gain.values.at(0);
  c.arm.p = manip.p;
  for (int j = 0; j < kJoints; ++j) {
    const JointSpec& joint = robot.joint(j);
    c.arm.length[j] = joint.length;
    c.arm.lower[j] = joint.lower;
    c.arm.upper[j] = joint.upper;
    c.arm.margin[j] = margin.margin.values.size() == 1 ? margin.margin.values[0] : margin.margin.values.at(j);
    c.theta0[j] = s.theta0(j);
    if (j == 0) {
      c.arm.joint1_speed = dynamic_cast<const ConstantLaw&>(*joint.velocity_limit).settings().upper;
    } else {
      const auto& law = dynamic_cast<const PushRodLaw&>(*joint.velocity_limit).settings();
      c.arm.a[j] = law.a;
      c.arm.b[j] = law.b;
      c.arm.s = law.s;
      c.arm.sigma_min = law.sigma_min;
      c.arm.sigma_max = law.sigma_max;
    }
  }
  c.steps = s.steps();
  c.tau = s.tau;
  Eigen::VectorXd r(2), v(2);
  for (int k = 0; k <= c.steps; ++k) {
    s.path->evaluate(k == c.steps ? s.duration : k * s.tau, r, v);
    c.r_d.insert(c.r_d.end(), {r(0), r(1)});
    c.r_d_dot.insert(c.r_d_dot.end(), {v(0), v(1)});
  }
  // The letter: the path's length is h (1 + 1/3 + pi/4 + sqrt((5/12)^2 + 1/4)), r_d(0) is its origin, and the
  // paper's scenarios keep the default rotation of 180 degrees. Checked against the scenario's path below.
  const double per_height = 1.0 + 1.0 / 3.0 + std::numbers::pi / 4.0 + std::sqrt(25.0 / 144.0 + 0.25);
  c.letter.height = s.path->length() / per_height;
  c.letter.psi = std::numbers::pi;
  double f0[2];
  end_effector(c.arm, c.theta0, f0);
  c.letter.offset[0] = c.r_d[0] - f0[0];
  c.letter.offset[1] = c.r_d[1] - f0[1];
  for (int k = 0; k <= c.steps; k += 97) {
    double at[2], rate[2];
    letter_r_at(c.letter, f0[0] + c.letter.offset[0], f0[1] + c.letter.offset[1], c.steps * c.tau, k * c.tau, at, rate);
    const auto K = static_cast<std::size_t>(k);
    const double err = std::max({std::abs(at[0] - c.r_d[2 * K]), std::abs(at[1] - c.r_d[2 * K + 1]),
                                 std::abs(rate[0] - c.r_d_dot[2 * K]), std::abs(rate[1] - c.r_d_dot[2 * K + 1])});
    if (!(err <= 1e-12)) {
      throw std::invalid_argument("the scenario's path is not the baseline's letter R (it differs by " +
                                  std::to_string(err) + " at step " + std::to_string(k) + ")");
    }
  }
  return c;
}

}  // namespace redres::baseline
