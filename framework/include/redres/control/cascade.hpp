#pragma once
/// @file
/// Strict priorities (docs/tasks.md): a scheme whose objectives and tasks sit at several priority levels is solved
/// one QP per level, highest first, by the scenario's LVI engine. Level l's QP is
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
/// eps's bias along the rows' weak directions from O(eps / sigma^2) to its cube. A level below the first whose tasks
/// cannot all be met (its QP fails) is solved again in least squares: its equality tasks' rows become (weight / 2) |J x
/// - d|^2 and its inequality rows get slack variables s with (weight / 2) |s|^2 (J_r x - s <= hi_r), so they are met as
/// well as the higher levels allow; the level's status is then `relaxed`. A level that fails even so keeps the higher
/// levels' answer: the step does not fail because a low-priority task cannot be met. A level whose objectives have a
/// quadratic term (a velocity norm) decides every joint velocity left free, so the levels below it are skipped. Level 0
/// is solved into the controller's own QP by its own engine, so that a failure there is the step's, handled by the
/// failure policy.
///
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

/// The levels of a cascaded scheme, for one controller.
class Cascade {
 public:
  /// For `scheme` (cascaded()) and the controller's `data`; `engine` is the controller's (level 0's), and each lower
  /// level gets an engine of its own of the same type and settings.
  Cascade(const Scheme& scheme, const SchemeData& data, const LviEngine& engine);
  Cascade(const Cascade&) = delete;
  Cascade& operator=(const Cascade&) = delete;
  ~Cascade();

  /// Sizes `qp` as level 0's QP and names its sources and rows.
  void setup_first(QpProblem& qp) const;
  /// Builds the constraints' rows, every task's rows and level 0's QP into `qp` (throws std::invalid_argument as
  /// Scheme::build does, naming the plugin).
  void build_first(const Context& ctx, SchemeData& data, QpProblem& qp);
  /// After level 0 solved with answer x0: solves the levels below; writes levels[1..] (levels[0] is the
  /// controller's) and x, the answer of the lowest level solved. Allocation-free.
  void solve_rest(const Context& ctx, SchemeData& data, const Eigen::VectorXd& x0, std::vector<LevelInfo>& levels,
                  Eigen::VectorXd& x);
  /// Level 0 (solved by the caller into `qp` with `engine`, answer in `r`): when it is a least squares, its proximal
  /// steps (below), each adding its iterations to `iterations`. Allocation-free.
  void refine_first(QpProblem& qp, LviEngine& engine, SolverResult& r, int& iterations);
  /// Writes level 0's tasks' error at x into levels[0].task_error.
  void first_task_error(const SchemeData& data, const Eigen::VectorXd& x, LevelInfo& info) const;
  /// Forgets the lower levels' engines' warm starts.
  void reset();
  /// The number of levels.
  [[nodiscard]] int level_count() const noexcept { return static_cast<int>(levels_.size()); }

 private:
  struct Level;
  struct RowTag;
  void size_level(int l, QpProblem& qp, bool least_squares, int held_rows) const;
  void assemble(int l, const SchemeData& data, QpProblem& qp, bool least_squares);
  void hold(int l, const SchemeData& data, const Eigen::VectorXd& x);
  [[nodiscard]] double task_error(int l, const SchemeData& data, const Eigen::VectorXd& x) const;
  void describe_level(int l, TextSink& out) const;
  void refine(QpProblem& qp, LviEngine& engine, SolverResult& r, int& iterations);

  const Scheme* scheme_;
  int n_ = 0;
  double eps_ = 0.0;
  QpProblem base_;  // the constraints' rows and bounds, once per step
  QpProblem obj_;   // one level's objectives
  QpBuilder::WrittenW obj_w_ = QpBuilder::WrittenW::kNone;
  std::vector<std::unique_ptr<Level>> levels_;
  Eigen::MatrixXd held_J_, held_A_;  // the higher levels' optima, as rows
  Eigen::VectorXd held_d_, held_b_;
  int held_eq_ = 0, held_in_ = 0;                    // rows held so far this step
  std::vector<std::vector<std::string>> row_names_;  // each task's row names (for diagnoses)
  std::string note_;                                 // a failed try's text while the next writes
  bool least_squares_terms_ = false;                 // the last assembled level has terms in W (scaled)
  Eigen::VectorXd prox_;                             // the centre of the last proximal step
  Eigen::VectorXd keep_;                             // the answer before a proximal step
};

}  // namespace redres
