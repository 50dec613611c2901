#pragma once
/// @file
/// The priority levels of a scheme (docs/tasks.md), which the Controller runs for every scheme: one QP per level,
/// highest first, each with an engine of the scenario's type and settings. A scheme with one level is one QP (the
/// paper's), exactly as Scheme::build() writes it. With several, level l's QP is
///
///   minimise   x'(W_l + eps c I)x / 2 + zeta_l'x  (its objectives, its soft tasks' least squares, damping; c is
///                                                  W_l's largest diagonal entry, and W_l = 0 becomes I)
///   subject to the constraints' rows and bounds   (hard at every level)
///              its equality and inequality tasks' rows
///              every higher level's optimum held: its equality and soft tasks' rows J x = J x*, its inequality
///              tasks' rows at what they reached (J_r x <= max(hi_r, J_r x*)), and the value of its linear
///              objectives (zeta' x <= zeta' x*).
///
/// eps (the scheme's `regularization`, relative to the level's own terms) makes every level's answer unique; it is not
/// held, so it decides nothing that a lower level wants. Each level's QP is scaled so that its W's largest diagonal
/// entry is 1 (the same minimiser, a better conditioned problem for the engine). A least-squares level (soft tasks,
/// or a retry) is solved twice more with eps |x - x_k|^2 / 2 about its last answer x_k (proximal steps), which takes
/// eps's bias along the rows' weak directions from O(eps / sigma^2) to its cube. A level whose tasks cannot all be met
/// (its QP fails) is solved again in least squares when there is a level above it: its equality tasks' rows become
/// (weight / 2) |J x - d|^2 and its inequality rows get slack variables s with (weight / 2) |s|^2 (J_r x - s <= hi_r),
/// so they are met as well as the higher levels allow; the level's status is then `relaxed`. A level that fails even
/// so keeps the higher levels' answer: the step does not fail because a low-priority task cannot be met. The first
/// level has no level above it: its failure is the step's, which the controller's failure policy handles (on
/// problem(0)). A level whose objectives have a quadratic term (a velocity norm) decides every joint velocity left
/// free, so the levels below it are skipped.
///
/// Every level's task rows are written by write_task_terms() (control/task.hpp), the one writer of task rows.
/// Everything is sized at construction; a step allocates nothing.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "redres/control/scheme.hpp"
#include "redres/qp/lvi.hpp"

namespace redres {

/// One priority level's outcome at a step (StepOutput::levels).
struct LevelInfo {
  int priority = 0;                             //!< the level's priority
  SolverStatus status = SolverStatus::kNotRun;  //!< solved; relaxed (its tasks in least squares); not_run (skipped);
                                                //!< else why it failed (the step keeps the higher levels' answer)
  int iterations = 0;                           //!< the engine's iterations at this level (both tries)
  double residual = 0.0;                        //!< the engine's residual at this level
  double task_error = 0.0;  //!< the largest miss of its tasks' rows at the answer: |J x - d| (equality, soft) or
                            //!< the excess over a bound (inequality)
  std::string diagnosis;    //!< why it was relaxed, skipped or failed (empty when solved)
};

/// The levels of a scheme, for one controller.
class Cascade {
 public:
  /// For `scheme` and the controller's `data`: the first level is solved by `engine` (the controller's, which must
  /// outlive the cascade), and each level below gets an engine of its own of the same type and settings.
  Cascade(const Scheme& scheme, const SchemeData& data, LviEngine& engine);
  Cascade(const Cascade&) = delete;
  Cascade& operator=(const Cascade&) = delete;
  ~Cascade();

  /// Solves one step: the constraints' and the tasks' rows once, then each level in turn. `info` becomes the first
  /// level's engine's outcome, with the iterations of every level; levels() each level's. Returns the answer of the
  /// lowest level solved (n joint velocities or accelerations, valid until the next call), or nullptr when the first
  /// level did not solve (then no level below ran). Throws std::invalid_argument as Scheme::build() does, naming the
  /// plugin that gave a non-finite entry. Allocation-free.
  const Eigen::VectorXd* solve(const Context& ctx, SchemeData& data, SolverInfo& info) {
    return several_ ? solve_levels(ctx, data, info) : solve_one(ctx, data, info);
  }
  /// Each level's outcome at the last step, highest first.
  [[nodiscard]] const std::vector<LevelInfo>& levels() const noexcept { return info_; }
  /// The QP that level l solved last, and its engine's result (level 0: the step's QP, which a failure policy reads).
  [[nodiscard]] const QpProblem& problem(int level) const;
  [[nodiscard]] const SolverResult& result(int level) const;
  /// Forgets every level's engine's warm start.
  void reset();
  /// The number of levels.
  [[nodiscard]] int level_count() const noexcept { return static_cast<int>(levels_.size()); }

 private:
  struct Level;
  struct RowTag;
  struct Slot;
  void size_level(int l, QpProblem& qp, bool least_squares, int held_rows) const;
  void assemble(int l, const SchemeData& data, QpProblem& qp, bool least_squares);
  void hold(int l, const SchemeData& data, const Eigen::VectorXd& x);
  [[nodiscard]] double task_error(int l, const SchemeData& data, const Eigen::VectorXd& x) const;
  [[nodiscard]] double hard_miss(int l, const SchemeData& data, const Eigen::VectorXd& x, double& limit) const;
  void describe_level(int l, TextSink& out) const;
  const Eigen::VectorXd* solve_one(const Context& ctx, SchemeData& data, SolverInfo& info);
  const Eigen::VectorXd* solve_levels(const Context& ctx, SchemeData& data, SolverInfo& info);
  void refine(QpProblem& qp, LviEngine& engine, SolverResult& r, int& iterations);
  [[nodiscard]] const Slot& last_slot(int level) const;

  const Scheme* scheme_;
  int n_ = 0;
  double eps_ = 0.0;
  bool several_ = false;  // several levels: each is scaled, regularized and holds the levels above
  QpProblem base_;        // the constraints' rows and bounds, once per step
  QpProblem obj_;         // one level's objectives
  QpBuilder::WrittenW obj_w_ = QpBuilder::WrittenW::kNone;
  std::vector<std::unique_ptr<Level>> levels_;
  std::vector<LevelInfo> info_;
  Eigen::MatrixXd held_J_, held_A_;  // the higher levels' optima, as rows
  Eigen::VectorXd held_d_, held_b_;
  int held_eq_ = 0, held_in_ = 0;                    // rows held so far this step
  std::vector<int> used_slot_;                       // the slot each level solved in at the last step
  std::vector<std::vector<std::string>> row_names_;  // each task's row names (for diagnoses)
  std::string note_;                                 // a failed try's text while the next writes
  bool least_squares_terms_ = false;                 // the last assembled level has terms in W (scaled)
  Eigen::VectorXd prox_;                             // the centre of the last proximal step
  Eigen::VectorXd keep_;                             // the answer before a proximal step
  Eigen::VectorXd x_;                                // several levels: the answer of the lowest level solved
  Slot* first_ = nullptr;                            // one level: its only slot
};

}  // namespace redres
