#pragma once
/// @file
/// The per-step API for a caller's own control loop: step(theta, t) evaluates the kinematics, the desired path,
/// builds the QP from the scheme's plugins, solves it with the LVI engine and returns theta_dot with the solver's
/// status. Everything is sized at construction; step() allocates nothing and takes bounded time (the engine's
/// iteration cap).

#include <algorithm>
#include <memory>

#include <Eigen/Core>

#include "redres/control/brake.hpp"
#include "redres/control/cascade.hpp"
#include "redres/control/failure_policy.hpp"
#include "redres/control/orientation_reference.hpp"
#include "redres/control/path.hpp"
#include "redres/control/scheme.hpp"
#include "redres/qp/lvi.hpp"

namespace redres {

/// One control step's outcome, owned by the caller: step() writes into it, and nothing else does, so two outputs
/// (e.g. the two stages of Heun's method) never alias. Make one with Controller::make_output() (sized once);
/// step() then reuses its buffers without allocating (the diagnosis text of a failed step excepted).
struct StepOutput {
  /// The velocity command (n): at the velocity level the QP's x, inside the merged bounds; at the acceleration level
  /// theta_dot + tau x. A braked step's braking command; zero when the step held (the unconverged iterate is never
  /// handed out: Controller::result() keeps it).
  Eigen::VectorXd theta_dot;
  /// The commanded acceleration (n): at the acceleration level the QP's x; at the velocity level (theta_dot -
  /// theta_dot_prev) / tau. What the robot's acceleration limits bound.
  Eigen::VectorXd theta_ddot;
  SolverInfo info;              //!< status, iterations, residual, engine, diagnosis
  double task_row_error = 0.0;  //!< for a `relaxed` step, max_r |J_r theta_dot - d_r|: how far the equality rows
                                //!< are missed (0 for every other status)
  /// With several priority levels (Scheme::cascaded()): each level's outcome, highest first (info is level 0's, with
  /// the iterations of every level); empty otherwise.
  std::vector<LevelInfo> levels;
};

struct Scenario;

/// Runs the scheme for one robot. The robot, scheme, engine and path must outlive the controller.
class Controller {
 public:
  /// `path` may be null when the caller supplies r_d and r_d_dot itself. T is the task duration (s), tau the
  /// step (s), both visible to plugins through the Context.
  /// The controller makes its own data of every plugin (Scheme::make_data()), so several controllers can share one
  /// scheme, each in its own thread.
  Controller(const RobotModel& robot, const Scheme& scheme, LviEngine& engine, const Path* path, double T, double tau);
  /// The same with an engine of its own (not null), e.g. EngineSpec::make()'s.
  Controller(const RobotModel& robot, const Scheme& scheme, std::unique_ptr<LviEngine> engine, const Path* path,
             double T, double tau);
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  /// The controller that simulate() runs for `scenario`: its robot, scheme and path, T and tau, an engine of its own
  /// made from the scenario's [solver] (with its own warm start), its orientation turn, the kinematics the recorded
  /// run reads (w, without its gradient unless a plugin needs it), and its failure policy. The scenario is only read:
  /// any number of controllers of one scenario may run at once, each in its own thread; the scenario must outlive
  /// them. (Defined in run/, beside the scenario.)
  [[nodiscard]] static std::unique_ptr<Controller> from_scenario(const Scenario& scenario);

  /// An output sized for this controller.
  [[nodiscard]] StepOutput make_output() const;

  /// One step at (theta, t) with the desired values from the path. Orientation rows, if the task has them, hold the
  /// orientation reference: the one set with set_orientation_reference(), or else the end effector's orientation
  /// at the first such step after construction or reset().
  void step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t, StepOutput& out);
  /// The same with the joint velocity the caller measured (size n, finite): plugins read it as
  /// Context::theta_dot_measured during this step.
  void step(const Eigen::Ref<const Eigen::VectorXd>& theta, const Eigen::Ref<const Eigen::VectorXd>& theta_dot_measured,
            double t, StepOutput& out);
  /// Steps with caller-supplied r_d, r_d_dot and r_d_ddot (size reference_dim() each): the acceleration level's
  /// form (at the velocity level r_d_ddot is not read).
  void step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t, const Eigen::Ref<const Eigen::VectorXd>& r_d,
            const Eigen::Ref<const Eigen::VectorXd>& r_d_dot, const Eigen::Ref<const Eigen::VectorXd>& r_d_ddot,
            StepOutput& out);
  /// Solves this step again at another state (Heun's second stage, at the Euler prediction): the plugins see the same
  /// previous command as the step's first solve, and the step's command stays the first solve's unless
  /// set_applied() says otherwise.
  void reevaluate(const Eigen::Ref<const Eigen::VectorXd>& theta, double t, StepOutput& out);
  /// The command the caller actually applied this step (e.g. Heun's average of its two stages): the next step's
  /// Context::theta_dot_prev. By default it is the step's own theta_dot (zeros for a held step).
  void set_applied(const Eigen::Ref<const Eigen::VectorXd>& theta_dot);
  /// The period of the steps from now on (s, > 0), when the caller's loop runs at another one than the scenario's:
  /// Context::tau.
  void set_period(double tau);
  /// One step with caller-supplied r_d and r_d_dot (size reference_dim(): every row of the position or pose, also
  /// those a subset of task rows leaves free, which are not used).
  void step(const Eigen::Ref<const Eigen::VectorXd>& theta, double t, const Eigen::Ref<const Eigen::VectorXd>& r_d,
            const Eigen::Ref<const Eigen::VectorXd>& r_d_dot, StepOutput& out);

  /// For tasks with orientation rows: the orientation the path's steps hold (planar: the angle in z; spatial: a
  /// rotation vector).
  void set_orientation_reference(const Eigen::Vector3d& rotation_vector) { orientation_.set(rotation_vector); }
  /// Makes the path's steps turn the orientation instead of holding it (OrientationReference::set_turn: from the
  /// reference R_0 at t = 0 to Rot(turn) R_0 at t = T, cycloidal timing). Planar: only turn.z() is used.
  void set_orientation_turn(const Eigen::Vector3d& turn) { orientation_.set_turn(turn); }
  /// The orientation reference (meaningful once set or captured).
  [[nodiscard]] const Eigen::Vector3d& orientation_reference() const noexcept { return orientation_.orientation(); }
  /// Computes at least this much kinematics each step (e.g. kManipulability to record w with any scheme).
  void set_kinematics_level(KinematicsLevel level) { level_ = std::max(level_, level); }
  /// What a step does when its QP cannot be solved (status not `solved`). By default it holds: theta_dot = 0.
  /// With a weight > 0 it first solves the elastic QP instead: the same objective plus (weight / 2) |J x - d|^2,
  /// without the equality rows, and with every bound and inequality row kept, so that the arm yields inside every
  /// limit. When that solves, the step's status is `relaxed`, theta_dot is its answer and task_row_error says by
  /// how much the rows are missed; when it does not, the step holds with the first failure's status. weight = 0
  /// turns relaxation off. Allocates (a second engine of the same type and its QP): call it before the loop.
  void set_relaxation(double weight);
  /// The failure policy (control/failure_policy.hpp), with the elastic QP's weight (> 0; used by kRelax and kBrake)
  /// and the position error (m, > 0) above which kBrake tries the elastic QP first. kStop gives up at once as kHold
  /// does (a robot with acceleration limits brakes); the caller's loop ends there. Throws std::invalid_argument for
  /// kBrake or kHold on a robot that has (kHold) or lacks (kBrake) acceleration limits on every joint. The default is
  /// kBrake for a robot with acceleration limits, else kRelax (the arm keeps moving within its bounds and returns to
  /// the task once it is feasible again); kHold stays available by name. Allocates: call it before the loop.
  void set_failure_policy(FailurePolicy policy, double relax_weight = 1e4, double recover_error = 1e-3);
  [[nodiscard]] FailurePolicy failure_policy() const noexcept { return policy_; }
  /// Forgets the engine's warm start and a captured (not an explicitly set) orientation reference.
  void reset();

  /// Kinematics, QP, desired values and the full solver result of the last step.
  [[nodiscard]] const KinematicsData& kinematics() const noexcept { return kin_; }
  /// The QP of the first priority level (the step's: the paper's one QP when the scheme has one level).
  [[nodiscard]] const QpProblem& qp() const { return cascade_->problem(0); }
  [[nodiscard]] const Eigen::VectorXd& r_d() const noexcept { return r_d_; }
  [[nodiscard]] const Eigen::VectorXd& r_d_dot() const noexcept { return r_d_dot_; }
  /// The last step's desired task acceleration (acceleration level; zeros at the velocity level).
  [[nodiscard]] const Eigen::VectorXd& r_d_ddot() const noexcept { return r_d_ddot_; }
  /// The previous step's command as this step's plugins saw it (Context::theta_dot_prev).
  [[nodiscard]] const Eigen::VectorXd& theta_dot_prev() const noexcept { return prev_; }
  /// The velocity-limit laws at the last step's theta (n each).
  [[nodiscard]] const Eigen::VectorXd& velocity_lower() const noexcept { return vlo_; }
  [[nodiscard]] const Eigen::VectorXd& velocity_upper() const noexcept { return vhi_; }
  /// The acceleration and jerk limits at the last step's theta (n each; zeros for a robot without them).
  [[nodiscard]] const Eigen::VectorXd& acceleration_lower() const noexcept { return acc_lo_; }
  [[nodiscard]] const Eigen::VectorXd& acceleration_upper() const noexcept { return acc_hi_; }
  [[nodiscard]] const Eigen::VectorXd& jerk_lower() const noexcept { return jerk_lo_; }
  [[nodiscard]] const Eigen::VectorXd& jerk_upper() const noexcept { return jerk_hi_; }
  /// The first level's engine's result (the unconverged iterate of a failed step included).
  [[nodiscard]] const SolverResult& result() const { return cascade_->result(0); }
  /// Every priority level's QP and outcome at the last step (control/cascade.hpp).
  [[nodiscard]] const Cascade& levels() const noexcept { return *cascade_; }
  [[nodiscard]] const RobotModel& robot() const noexcept { return *robot_; }
  /// The name of the engine it solves with.
  [[nodiscard]] std::string_view engine_name() const { return engine_->name(); }
  /// The scheme it runs.
  [[nodiscard]] const Scheme& scheme() const noexcept { return *scheme_; }
  /// This controller's data of the scheme's plugins, as the last step left it (e.g. the distances of a collision
  /// constraint): what violated(), the outputs' record() and summarise() read.
  [[nodiscard]] const SchemeData& plugin_data() const noexcept { return *data_; }
  /// The same, shared: it stays alive after the controller (a run's summary reads it).
  [[nodiscard]] std::shared_ptr<const SchemeData> shared_plugin_data() const noexcept { return data_; }

 private:
  void solve(double t, StepOutput& out);
  void begin_step();                     // the previous step's command becomes theta_dot_prev
  void end_step(const StepOutput& out);  // this step's command and status, for the next
  bool relax(StepOutput& out);           // the elastic QP; false when it fails too
  void brake(StepOutput& out);           // the braking command
  void give_up(StepOutput& out);         // a step that stays failed: brakes (acceleration limits, not kHold) or holds
  void apply(const Eigen::VectorXd& x, StepOutput& out);        // x (the QP's) into theta_dot and theta_ddot
  [[nodiscard]] const Eigen::VectorXd& base() const noexcept {  // the velocity before this step
    return ctx_.order == ControlOrder::kVelocity ? prev_ : v_;
  }

  const RobotModel* robot_;
  const Scheme* scheme_;
  std::shared_ptr<SchemeData> data_;       // the plugins' per-controller data (never null)
  std::unique_ptr<LviEngine> own_engine_;  // the engine, when the controller owns it
  LviEngine* engine_;
  const Path* path_;
  KinematicsData kin_;
  Eigen::VectorXd r_d_, r_d_dot_, r_d_ddot_;
  Eigen::VectorXd vlo_, vhi_;         // the velocity-limit laws at theta, once per step
  OrientationReference orientation_;  // the orientation rows of r_d and r_d_dot under a path
  KinematicsLevel level_ = KinematicsLevel::kPosition;
  Context ctx_;
  double relax_weight_ = 0.0;               // set_relaxation(); 0: hold
  std::string note_;                        // a failed step's text while relax() writes its own before it
  Eigen::VectorXd prev_, prev2_, pending_;  // theta_dot_prev, theta_dot_prev2, this step's applied command
  Eigen::VectorXd measured_;                // the caller's measured joint velocity, during a step that has one
  SolverStatus pending_status_ = SolverStatus::kNotRun;
  bool have_pending_ = false;          // a step was made whose command is not yet theta_dot_prev
  bool started_ = false;               // the plugins were told that the run starts
  Eigen::VectorXd v_;                  // acceleration level: the joint velocity at this step
  Eigen::VectorXd acc_lo_, acc_hi_;    // the acceleration limits at theta, once per step (robots that have them)
  Eigen::VectorXd jerk_lo_, jerk_hi_;  // the jerk limits at theta, once per step (robots that have them)
  FailurePolicy policy_ = FailurePolicy::kHold;  // the constructor sets the default (kBrake or kRelax)
  double recover_error_ = 1e-3;       // kBrake: the position error above which the elastic QP goes first
  ElasticFallback fallback_;          // the elastic QP of kRelax and kBrake, with its engine
  std::unique_ptr<Cascade> cascade_;  // the scheme's priority levels, one QP each (never null)
};

}  // namespace redres
