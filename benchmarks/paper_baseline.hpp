#pragma once
// The baseline of the step-loop benchmarks: a hand-written, fixed-size loop of the paper's TVCMM scheme on its
// planar 6-DOF push-rod arm, with no part of the framework: closed-form planar kinematics (f, J, w = det(J J') and
// its gradient from suffix sums), the merged bounds (eq. 9 with the safety margin, and the push-rod law of eq. 2),
// and the QP  min x'x/2 - p(t) grad w' x  s.t.  J x = r_d_dot + K (r_d - f),  lo <= x <= hi  solved by semismooth
// Newton on the two multipliers of J x = d (x = clip(-zeta - J'y, lo, hi)), warm-started, then Euler integration.
// It records theta, x and w of every step into preallocated memory, as the framework's run does. The desired path is
// the paper's letter R, evaluated inside the loop as the framework does (run_letter_r), or, for comparison, a table
// of r_d and r_d_dot per step computed before the loop (run).

#include <array>
#include <cstddef>
#include <vector>

namespace redres::baseline {

inline constexpr int kJoints = 6;
using Joints = std::array<double, kJoints>;

/// The paper's arm (Table I) and the scheme's constants.
struct PaperArm {
  Joints length{};                          // l_i (m)
  Joints lower{}, upper{};                  // theta^-, theta^+ (rad)
  Joints margin{};                          // safety margin (rad)
  double kappa = 4.0;                       // eq. 9
  double gain = 8.0;                        // K (1/s)
  double p = 2.0;                           // p(t) = p sin(pi t / T)
  double joint1_speed = 0.0;                // joint 1: constant law +-joint1_speed (rad/s)
  Joints a{}, b{};                          // push-rod triangles of joints 2..6 (m); entry 0 unused
  double s = 0.0;                           // push-rod elongation per motor turn (m/rot)
  double sigma_min = 0.0, sigma_max = 0.0;  // motor rates (rot/s)
};

/// One run's record: per step theta (6), x (6), w; and the iterations of the solves.
struct Record {
  std::vector<double> rows;  // (steps + 1) x 13
  long iterations = 0;
  int failures = 0;  // solves that did not converge
};

/// The letter R of height h (the project's definition: stem, bowl, leg, each stroke timed by the cycloidal law over
/// its share of T by length), rotated by psi about its origin, which sits at f(theta0) + offset.
struct LetterR {
  double height = 0.15;   // h (m)
  double psi = 0.0;       // rotation (rad)
  double offset[2] = {};  // origin shift from f(theta0) (m)
};

/// Runs the scheme from theta0 over steps + 1 steps of tau (T = steps * tau), with r_d and r_d_dot given per step
/// as 2 (steps + 1) values each. `record` must hold (steps + 1) * 13 values. Returns theta(T).
Joints run(const PaperArm& arm, const Joints& theta0, const double* r_d, const double* r_d_dot, int steps, double tau,
           Record& record);

/// The letter's r_d and r_d_dot at time t of T, with its origin at (ox, oy) (for the set-up's check).
void letter_r_at(const LetterR& letter, double ox, double oy, double T, double t, double r[2], double v[2]);

/// f(theta) of the arm (for the set-up).
void end_effector(const PaperArm& arm, const Joints& theta, double f[2]);

/// The same run with the letter R evaluated at each step.
Joints run_letter_r(const PaperArm& arm, const LetterR& letter, const Joints& theta0, int steps, double tau,
                    Record& record);

}  // namespace redres::baseline
