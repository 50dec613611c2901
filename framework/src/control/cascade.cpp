#include "redres/control/cascade.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "redres/common/hot.hpp"
#include "redres/control/engine_registry.hpp"

namespace redres {

namespace {
// How much more tightly the levels below the first are solved than the first (Cascade's constructor).
constexpr double kHeldTighter = 1e-4;
}  // namespace

namespace {
// A held row whose part outside the rows held before it is below this (relative to its norm) adds nothing.
constexpr double kDependent = 1e-6;
}  // namespace

/// What an inequality row of a level's QP past the constraints' stands for.
struct Cascade::RowTag {
  int task = -1;  // the task (index in the scheme), or -1: a higher level's objectives held
  int row = 0;    // the task's row
  bool upper = true;
  bool held = false;
  int priority = 0;  // the level it comes from
};

struct Cascade::Level {
  int priority = 0;
  std::vector<int> tasks, objectives;
  int eq_tasks = 0;  // the rows of its equality tasks
  int in_tasks = 0;  // the inequality rows of its inequality tasks (and, in least squares, its slacks)
  int held_eq = 0;   // at most this many rows held from the levels above (an orthonormal basis of their span)
  int held_in = 0;   // inequality rows held from the levels above
  std::vector<RowTag> in_tags;  // its QP's inequality rows past the constraints'
  bool has_ls = false;          // below the first, with equality or inequality tasks: a least-squares retry
  // Equality tasks alone (no soft or inequality task, no objective): its least squares is the best fit of its rows
  // with the levels above held, so a relaxed level can be solved in least squares first at the next step.
  bool ls_first = false;
  bool relaxed_last = false;  // its answer at the last step was the least squares
  // One QP (and its least-squares retry) per number of held rows, 0 to held_eq, each with its engine: the held rows'
  // rank is known only at the step, and a QP with fewer independent rows than rows would be degenerate.
  std::vector<std::unique_ptr<Slot>> slots;
};

struct Cascade::Slot {
  QpProblem qp, ls;
  std::unique_ptr<LviEngine> own, ls_engine;  // the level's engines (the first level's is the controller's)
  LviEngine* engine = nullptr;
  // Below the first level, when the level's engine is not newton: newton, tried on the level's QP when that engine
  // fails without finding the rows unmeetable, before the least-squares retry. newton itself goes on to projection
  // (its fallback) and is not followed by nlopt, which allocates in every solve.
  std::unique_ptr<LviEngine> next;
  SolverResult result, ls_result, next_result;
  bool used_ls = false;  // the last step's answer came from the least-squares retry
};

Cascade::~Cascade() = default;

Cascade::Cascade(const Scheme& scheme, const SchemeData& data, LviEngine& engine)
    : scheme_(&scheme), n_(scheme.robot().dof()), eps_(scheme.regularization()), several_(scheme.levels().size() > 1) {
  scheme.setup_constraints(base_, data);
  obj_.resize(n_, 0, 0);
  const auto& tasks = scheme.tasks();
  for (const auto& t : tasks) {
    std::vector<std::string> names;
    for (int r = 0; r < t->rows(); ++r) names.push_back(t->row_name(r));
    row_names_.push_back(std::move(names));
  }
  int held_eq = 0, held_in = 0;
  std::vector<RowTag> held_tags;
  for (const SchemeLevelSpec& spec : scheme.levels()) {
    auto level = std::make_unique<Level>();
    level->priority = spec.priority;
    level->tasks = spec.tasks;
    level->objectives = spec.objectives;
    level->held_eq = std::min(held_eq, n_);
    level->held_in = held_in;
    for (int k : spec.tasks) {
      const Task& t = *tasks[static_cast<std::size_t>(k)];
      if (t.mode() == TaskMode::kEquality) level->eq_tasks += t.rows();
      if (t.mode() == TaskMode::kInequality) {
        level->in_tasks += t.inequality_rows();
        for (int r = 0; r < t.rows(); ++r) {
          if (t.has_upper(r)) level->in_tags.push_back({k, r, true, false, spec.priority});
          if (t.has_lower(r)) level->in_tags.push_back({k, r, false, false, spec.priority});
        }
      }
    }
    level->in_tags.insert(level->in_tags.end(), held_tags.begin(), held_tags.end());
    // What this level leaves held for those below it.
    for (int k : spec.tasks) {
      const Task& t = *tasks[static_cast<std::size_t>(k)];
      if (t.mode() == TaskMode::kInequality) {
        held_in += t.inequality_rows();
        for (int r = 0; r < t.rows(); ++r) {
          if (t.has_upper(r)) held_tags.push_back({k, r, true, true, spec.priority});
          if (t.has_lower(r)) held_tags.push_back({k, r, false, true, spec.priority});
        }
      } else {
        held_eq += t.rows();
      }
    }
    if (!spec.objectives.empty()) {
      ++held_in;
      held_tags.push_back({-1, 0, true, true, spec.priority});
    }
    level->has_ls = !levels_.empty() && level->eq_tasks + level->in_tasks > 0;
    level->ls_first = level->has_ls && level->in_tasks == 0 && spec.objectives.empty() &&
                      std::all_of(spec.tasks.begin(), spec.tasks.end(), [&](int k) {
                        return tasks[static_cast<std::size_t>(k)]->mode() == TaskMode::kEquality;
                      });
    levels_.push_back(std::move(level));
  }
  held_J_ = Eigen::MatrixXd::Zero(std::min(held_eq, n_), n_);
  held_d_ = Eigen::VectorXd::Zero(held_J_.rows());
  held_A_ = Eigen::MatrixXd::Zero(held_in, n_);
  held_b_ = Eigen::VectorXd::Zero(held_in);
  // The levels below the first hold the optima of those above as rows: they are solved kHeldTighter times more
  // tightly than the first (1e-10 at the default 1e-6), so that a lower level cannot gain what a higher one loses
  // by the tolerance (docs/tasks.md).
  SolverSettings settings = engine.settings();
  settings.tolerance = std::max(1e-14, settings.tolerance * kHeldTighter);
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    Level& L = *levels_[l];
    for (int rank = 0; rank <= L.held_eq; ++rank) {
      auto slot = std::make_unique<Slot>();
      size_level(static_cast<int>(l), slot->qp, false, rank);
      if (l == 0) {
        slot->engine = &engine;
      } else {
        slot->own = make_engine(std::string(engine.name()), settings);
        slot->engine = slot->own.get();
        if (engine.name() != "newton") {
          slot->next = make_engine("newton", settings);
          slot->next->setup(slot->qp.n(), slot->qp.m_eq(), slot->qp.m_in(), slot->next_result);
        }
      }
      slot->engine->setup(slot->qp.n(), slot->qp.m_eq(), slot->qp.m_in(), slot->result);
      if (L.has_ls) {
        slot->engine->set_singular_values(false);  // a failure is retried in least squares; the text is added then
        size_level(static_cast<int>(l), slot->ls, true, rank);
        slot->ls_engine = make_engine(std::string(engine.name()), settings);
        slot->ls_engine->setup(slot->ls.n(), slot->ls.m_eq(), slot->ls.m_in(), slot->ls_result);
      }
      L.slots.push_back(std::move(slot));
    }
  }
  info_.resize(levels_.size());
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    info_[l].priority = levels_[l]->priority;
    info_[l].diagnosis.reserve(kDiagnosisCapacity);
  }
  used_slot_.assign(levels_.size(), 0);
  note_.reserve(kDiagnosisCapacity);
  prox_ = Eigen::VectorXd::Zero(n_);
  x_ = Eigen::VectorXd::Zero(n_);
  first_ = levels_.front()->slots.front().get();
  Eigen::Index widest = n_;
  for (const auto& level : levels_) widest = std::max<Eigen::Index>(widest, n_ + level->in_tasks);
  keep_ = Eigen::VectorXd::Zero(widest);
}

void Cascade::size_level(int l, QpProblem& qp, bool least_squares, int held_rows) const {
  const Level& L = *levels_[static_cast<std::size_t>(l)];
  const int slack = least_squares ? L.in_tasks : 0;
  const int m_eq = base_.m_eq() + (least_squares ? 0 : L.eq_tasks) + held_rows;
  const int m_in = base_.m_in() + L.in_tasks + L.held_in;
  qp.resize(n_ + slack, m_eq, m_in);
  qp.source_names = base_.source_names;
  qp.variable_names = base_.variable_names;
  for (int s = 0; s < slack; ++s) qp.variable_names.push_back("slack " + std::to_string(s + 1));
  const int held_source = static_cast<int>(qp.source_names.size());
  if (several_) qp.source_names.push_back("the higher levels' optima, held");
  std::copy(base_.eq_source.begin(), base_.eq_source.end(), qp.eq_source.begin());
  std::copy(base_.in_source.begin(), base_.in_source.end(), qp.in_source.begin());
  int row = base_.m_eq();
  if (!least_squares) {
    for (int k : L.tasks) {
      const Task& t = *scheme_->tasks()[static_cast<std::size_t>(k)];
      if (t.mode() != TaskMode::kEquality) continue;
      for (int r = 0; r < t.rows(); ++r) qp.eq_source[static_cast<std::size_t>(row++)] = scheme_->task_source(k);
    }
  }
  for (int r = 0; r < held_rows; ++r) qp.eq_source[static_cast<std::size_t>(row++)] = held_source;
  for (std::size_t r = 0; r < L.in_tags.size(); ++r) {
    const RowTag& tag = L.in_tags[r];
    qp.in_source[static_cast<std::size_t>(base_.m_in()) + r] =
        tag.held ? held_source : scheme_->task_source(static_cast<std::size_t>(tag.task));
  }
  // The description of its inequality rows, capturing no more than std::function holds without allocating (a copy,
  // such as the elastic QP's, allocates nothing).
  qp.in_row_description = [this, l](int r, TextSink& out) {
    const int m_in_c = base_.m_in();
    if (r < m_in_c) {
      if (base_.in_row_description) base_.in_row_description(r, out);
      return;
    }
    const RowTag& tag = levels_[static_cast<std::size_t>(l)]->in_tags[static_cast<std::size_t>(r - m_in_c)];
    if (tag.task < 0) {
      out << "the value of priority " << tag.priority << "'s objectives, held";
      return;
    }
    out << "task '" << scheme_->tasks()[static_cast<std::size_t>(tag.task)]->name() << "' row '"
        << row_names_[static_cast<std::size_t>(tag.task)][static_cast<std::size_t>(tag.row)] << "' "
        << (tag.upper ? "upper" : "lower") << " bound";
    if (tag.held) out << " (priority " << tag.priority << ", held where it ended)";
  };
}

void Cascade::reset() {
  for (auto& level : levels_) {
    level->relaxed_last = false;
    for (auto& slot : level->slots) {
      slot->engine->reset();
      if (slot->ls_engine) slot->ls_engine->reset();
      if (slot->next) slot->next->reset();
    }
  }
}

const Cascade::Slot& Cascade::last_slot(int level) const {
  REDRES_REQUIRE(level >= 0 && level < level_count(), "Cascade", "0 <= level < level_count()");
  const std::size_t l = static_cast<std::size_t>(level);
  return *levels_[l]->slots[static_cast<std::size_t>(used_slot_[l])];
}

const QpProblem& Cascade::problem(int level) const {
  const Slot& s = last_slot(level);
  return s.used_ls ? s.ls : s.qp;
}

const SolverResult& Cascade::result(int level) const {
  const Slot& s = last_slot(level);
  return s.used_ls ? s.ls_result : s.result;
}

void Cascade::assemble(int l, const SchemeData& data, QpProblem& qp, bool least_squares) {
  const Level& L = *levels_[static_cast<std::size_t>(l)];
  const int n = n_;
  qp.clear();
  // The objective: the level's objectives, its soft tasks (and their damping). clear() left W zero: a diagonal W is
  // its diagonal.
  if (obj_.w_diagonal) {
    for (int i = 0; i < n; ++i) qp.W(i, i) = obj_.W(i, i);
  } else {
    qp.W.topLeftCorner(n, n) = obj_.W;
  }
  qp.zeta.head(n) = obj_.zeta;
  qp.w_diagonal = obj_.w_diagonal;
  // The constraints: rows and bounds.
  const int me = base_.m_eq(), mi = base_.m_in();
  qp.J.topLeftCorner(me, n) = base_.J;
  qp.d.head(me) = base_.d;
  qp.A.topLeftCorner(mi, n) = base_.A;
  qp.b.head(mi) = base_.b;
  qp.lo.head(n) = base_.lo;
  qp.hi.head(n) = base_.hi;
  std::copy_n(base_.lo_source.begin(), n, qp.lo_source.begin());
  std::copy_n(base_.hi_source.begin(), n, qp.hi_source.begin());
  // The level's tasks, through the one writer of task rows.
  int eq = me, in = mi, slack = least_squares ? n : -1;
  QpBuilder builder(qp);
  for (int k : L.tasks) {
    const Task& t = *scheme_->tasks()[static_cast<std::size_t>(k)];
    const TaskTerms& terms = static_cast<const TaskData&>(*data.tasks[static_cast<std::size_t>(k)]).rows;
    const int eq_rows = t.mode() == TaskMode::kEquality && !least_squares ? t.rows() : 0;
    const int in_rows = t.mode() == TaskMode::kInequality ? t.inequality_rows() : 0;
    builder.begin(scheme_->task_source(static_cast<std::size_t>(k)), 1.0, eq, eq_rows, in, in_rows);
    slack = write_task_terms(t, terms, builder, slack);
    eq += eq_rows;
    in += in_rows;
  }
  // Scaled so that its largest diagonal entry is 1 (the same minimiser; a level of equality rows alone, W = 0, gets
  // W = I), plus eps I: the regularization is relative to the level's own terms.
  double scale = 0.0;
  for (int i = 0; i < qp.n(); ++i) scale = std::max(scale, qp.W(i, i));  // the slacks' weights too
  if (scale > 0.0) {
    if (qp.w_diagonal) {
      for (int i = 0; i < n; ++i) qp.W(i, i) /= scale;
    } else {
      qp.W.topLeftCorner(n, n) /= scale;
    }
    qp.zeta.head(n) /= scale;
    for (int i = n; i < qp.n(); ++i) qp.W(i, i) /= scale;
  }
  for (int i = 0; i < n; ++i) qp.W(i, i) += scale > 0.0 ? eps_ : 1.0;
  least_squares_terms_ = scale > 0.0;
  // The higher levels' optima.
  qp.J.block(eq, 0, held_eq_, n) = held_J_.topRows(held_eq_);
  qp.d.segment(eq, held_eq_) = held_d_.head(held_eq_);
  qp.A.block(in, 0, L.held_in, n) = held_A_.topRows(L.held_in);
  qp.b.segment(in, L.held_in) = held_b_.head(L.held_in);
}

void Cascade::hold(int l, const SchemeData& data, const Eigen::VectorXd& x) {
  const Level& L = *levels_[static_cast<std::size_t>(l)];
  const int n = n_;
  for (int k : L.tasks) {
    const Task& t = *scheme_->tasks()[static_cast<std::size_t>(k)];
    const TaskTerms& terms = static_cast<const TaskData&>(*data.tasks[static_cast<std::size_t>(k)]).rows;
    if (t.mode() == TaskMode::kInequality) {
      for (int r = 0; r < t.rows(); ++r) {
        const double v = terms.J.row(r).dot(x);
        if (t.has_upper(r)) {
          held_A_.row(held_in_) = terms.J.row(r);
          held_b_(held_in_++) = std::max(terms.hi(r), v);
        }
        if (t.has_lower(r)) {
          held_A_.row(held_in_) = -terms.J.row(r);
          held_b_(held_in_++) = std::max(-terms.lo(r), -v);
        }
      }
      continue;
    }
    // Equality and soft rows: J x = J x*, kept as an orthonormal basis (modified Gram-Schmidt) of the rows held so
    // far, so that the held rows are independent (a row in their span adds nothing and is left out).
    for (int r = 0; r < t.rows(); ++r) {
      if (held_eq_ >= held_J_.rows()) break;  // n independent rows: x is decided
      auto q = held_J_.row(held_eq_);
      q = terms.J.row(r);
      const double norm0 = q.norm();
      if (!(norm0 > 0.0)) continue;
      for (int i = 0; i < held_eq_; ++i) q -= q.dot(held_J_.row(i)) * held_J_.row(i);
      for (int i = 0; i < held_eq_; ++i) q -= q.dot(held_J_.row(i)) * held_J_.row(i);  // twice is enough
      const double norm = q.norm();
      if (!(norm > kDependent * norm0)) continue;
      q /= norm;
      ++held_eq_;
    }
  }
  // Every held row's value at this level's answer (the rows held before keep theirs, up to the solve's tolerance).
  for (int i = 0; i < held_eq_; ++i) held_d_(i) = held_J_.row(i).dot(x);
  if (!L.objectives.empty()) {
    // The value of the level's objectives, linear in x once its other terms are held: zeta' x <= zeta' x*.
    const double v = obj_.zeta.dot(x);
    held_A_.row(held_in_) = obj_.zeta.transpose();
    held_b_(held_in_++) = v + 1e-9 * (1.0 + std::abs(v));
  }
  (void)n;
}

double Cascade::task_error(int l, const SchemeData& data, const Eigen::VectorXd& x) const {
  const Level& L = *levels_[static_cast<std::size_t>(l)];
  double worst = 0.0;
  for (int k : L.tasks) {
    const Task& t = *scheme_->tasks()[static_cast<std::size_t>(k)];
    const TaskTerms& terms = static_cast<const TaskData&>(*data.tasks[static_cast<std::size_t>(k)]).rows;
    for (int r = 0; r < t.rows(); ++r) {
      const double v = terms.J.row(r).dot(x);
      if (t.mode() == TaskMode::kInequality) {
        if (t.has_upper(r)) worst = std::max(worst, v - terms.hi(r));
        if (t.has_lower(r)) worst = std::max(worst, terms.lo(r) - v);
      } else {
        worst = std::max(worst, std::abs(v - terms.d(r)));
      }
    }
  }
  return worst;
}

double Cascade::hard_miss(int l, const SchemeData& data, const Eigen::VectorXd& x, double& limit) const {
  // The 2-norm of what the level's equality rows miss (a level solved in least squares first has no other rows), as
  // the engines' `infeasible` measures a fit of the rows (RowFit::miss_norm). `limit`: 1e-6 (1 + |d|), far above what
  // a least squares that meets its rows misses by (its solve's tolerance over the rows' conditioning, and eps's bias
  // after the proximal steps): a level is taken as unmeetable only where it clearly is, and otherwise the exact QP
  // decides.
  const Level& L = *levels_[static_cast<std::size_t>(l)];
  double sum = 0.0, d_max = 0.0;
  for (int k : L.tasks) {
    const TaskTerms& terms = static_cast<const TaskData&>(*data.tasks[static_cast<std::size_t>(k)]).rows;
    for (Eigen::Index r = 0; r < terms.d.size(); ++r) {
      const double e = terms.J.row(r).dot(x.head(n_)) - terms.d(r);
      d_max = std::max(d_max, std::abs(terms.d(r)));
      sum += e * e;
    }
  }
  limit = 1e-6 * (1.0 + d_max);
  return std::sqrt(sum);
}

void Cascade::describe_level(int l, TextSink& out) const {
  const Level& L = *levels_[static_cast<std::size_t>(l)];
  out << "priority " << L.priority << " (";
  const char* sep = "";
  for (int k : L.tasks) {
    out << sep << "task '" << scheme_->tasks()[static_cast<std::size_t>(k)]->name() << "'";
    sep = ", ";
  }
  for (int k : L.objectives) {
    out << sep << "objective '" << scheme_->objectives()[static_cast<std::size_t>(k)]->name() << "'";
    sep = ", ";
  }
  out << ")";
}

void Cascade::refine(QpProblem& qp, LviEngine& engine, SolverResult& r, int& iterations) {
  // A least squares whose rows leave directions free: eps |x|^2 / 2 biases its optimum by O(eps / sigma^2) along its
  // weak directions. Two proximal steps, eps |x - x_k|^2 / 2 about the last answer, take that bias to
  // O((eps / sigma^2)^3) (the same matrix: the engine starts warm). Should a step fail, the answer before it stays.
  const Eigen::Index m = r.x.size();
  keep_.head(m) = r.x;
  prox_.setZero();
  for (int step = 0; step < 2; ++step) {
    qp.zeta.head(n_) += eps_ * prox_;  // the previous step's centre out, this one's in
    prox_ = r.x.head(n_);
    qp.zeta.head(n_) -= eps_ * prox_;
    engine.solve_valid(qp, r);
    iterations += r.info.iterations;
    if (r.info.status != SolverStatus::kSolved) {
      r.x = keep_.head(m);
      r.info.status = SolverStatus::kSolved;  // the answer before the step, which was solved
      break;
    }
    keep_.head(m) = r.x;
  }
}

namespace {
// A level's outcome before the step decides it: not run, nothing counted, no text (its reserve kept).
void not_run(LevelInfo& level) {
  level.status = SolverStatus::kNotRun;
  level.iterations = 0;
  level.residual = 0.0;
  level.task_error = 0.0;
  keep_diagnosis_capacity(level.diagnosis);
  level.diagnosis.clear();
}
}  // namespace

REDRES_HOT const Eigen::VectorXd* Cascade::solve_one(const Context& ctx, SchemeData& data, SolverInfo& info) {
  // One level (the paper's scheme; the real-time path): Scheme::build() writes the step's QP in one pass, and the
  // controller's engine solves it. Nothing is held, scaled or refined.
  Slot& S = *first_;
  scheme_->build(ctx, S.qp, data);
  S.engine->solve_valid(S.qp, S.result);
  const SolverInfo& got = S.result.info;
  info.status = got.status;
  info.iterations = got.iterations;
  info.residual = got.residual;
  info.engine = got.engine;
  if (!got.diagnosis.empty() || !info.diagnosis.empty()) info.diagnosis.assign(got.diagnosis);  // within its reserve
  LevelInfo& level = info_[0];
  level.status = info.status;
  level.iterations = info.iterations;
  level.residual = info.residual;
  level.task_error = 0.0;
  if (!level.diagnosis.empty()) level.diagnosis.clear();
  if (info.status != SolverStatus::kSolved) {
    keep_diagnosis_capacity(level.diagnosis);
    TextSink(level.diagnosis) << "the step's QP (priority " << levels_[0]->priority << ") failed";
    return nullptr;
  }
  if (!levels_[0]->tasks.empty()) level.task_error = task_error(0, data, S.result.x);
  return &S.result.x;
}

const Eigen::VectorXd* Cascade::solve_levels(const Context& ctx, SchemeData& data, SolverInfo& info) {
  // The parts every level's QP is assembled from.
  scheme_->build_constraints(ctx, base_, data);
  scheme_->evaluate_tasks(ctx, data);
  held_eq_ = held_in_ = 0;
  // Why the levels below are skipped, once one is: -1 none, 0 nothing left to decide, 1 a level failed.
  int skip = -1;
  int decided_by = 0;
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    Level& L = *levels_[l];
    LevelInfo& level = info_[l];
    not_run(level);
    TextSink text(level.diagnosis);
    text.precision(6);
    if (skip >= 0) {
      L.relaxed_last = false;
      text << "skipped: ";
      if (skip == 0) {
        text << "nothing left to decide (";
        describe_level(decided_by, text);
        text << " decided every joint velocity)";
      } else {
        text << "a higher level failed";
      }
      continue;
    }
    used_slot_[l] = held_eq_;
    Slot& S = *L.slots[static_cast<std::size_t>(held_eq_)];
    const bool relaxed_before = L.ls_first && L.relaxed_last;
    L.relaxed_last = false;
    S.used_ls = false;
    obj_w_ = scheme_->build_objectives(ctx, static_cast<int>(l), obj_, data);
    SolverResult* answer = nullptr;
    LviEngine* solved_by = S.engine;
    // Whether the QP assembled last has least-squares terms and no objective: then its answer is refined.
    const auto refines = [&] { return least_squares_terms_ && obj_w_ == QpBuilder::WrittenW::kNone; };
    bool ls_solved = false;  // S.ls_result is this step's least squares (refined where refines)
    const auto solve_ls = [&] {
      assemble(static_cast<int>(l), data, S.ls, true);
      S.ls_engine->solve_valid(S.ls, S.ls_result);
      level.iterations += S.ls_result.info.iterations;
      if (S.ls_result.info.status == SolverStatus::kSolved && refines()) {
        refine(S.ls, *S.ls_engine, S.ls_result, level.iterations);
      }
      ls_solved = true;
    };
    const auto relax = [&] {
      answer = &S.ls_result;
      S.used_ls = true;
      L.relaxed_last = true;
      level.residual = S.ls_result.info.residual;
      level.status = SolverStatus::kRelaxed;
    };
    if (relaxed_before) {
      // Relaxed at the last step: the least squares first. With the levels above held, its answer is the best the
      // level's rows can be met; where it still misses them by more than the tolerance, they cannot be met and it is
      // the level's answer (the exact QP would only find its rows infeasible). Once it meets them, the exact QP is
      // solved as at any other step.
      solve_ls();
      double miss = 0.0, limit = 0.0;
      if (S.ls_result.info.status == SolverStatus::kSolved)
        miss = hard_miss(static_cast<int>(l), data, S.ls_result.x, limit);
      if (miss > limit) {
        relax();
        text << "its tasks cannot all be met below the higher levels (in least squares they still miss by " << miss
             << "): solved in least squares";
      }
    }
    if (answer == nullptr) {
      assemble(static_cast<int>(l), data, S.qp, false);
      S.engine->solve_valid(S.qp, S.result);  // assemble() wrote only checked entries
      if (l == 0) info = S.result.info;       // the step's outcome, before any proximal step
      level.iterations += S.result.info.iterations;
      level.residual = S.result.info.residual;
      level.status = S.result.info.status;
      const SolverStatus status = S.result.info.status;
      // Where the level's engine stopped short on a QP whose rows can be met, the next engine tries it.
      const auto next_solves = [&] {
        if (status == SolverStatus::kInfeasible || !S.next) return false;
        S.next->solve_valid(S.qp, S.next_result);
        level.iterations += S.next_result.info.iterations;
        return S.next_result.info.status == SolverStatus::kSolved;
      };
      if (status == SolverStatus::kSolved) {
        answer = &S.result;
      } else if (next_solves()) {
        text << to_string(status) << " with " << S.engine->name() << ", solved by " << S.next->name();
        level.status = SolverStatus::kSolved;
        level.residual = S.next_result.info.residual;
        answer = &S.next_result;
        solved_by = S.next.get();
      } else if (L.has_ls) {
        if (!ls_solved) solve_ls();
        if (S.ls_result.info.status == SolverStatus::kSolved) {
          relax();
          text << "its tasks cannot all be met below the higher levels (" << to_string(S.result.info.status)
               << "): solved in least squares";
        } else {
          note_.assign(S.ls_result.info.diagnosis);
        }
      }
      if (answer != nullptr && !S.used_ls && refines()) {
        refine(S.qp, *solved_by, *answer, level.iterations);
        level.residual = answer->info.residual;
      }
    }
    if (answer == nullptr && l == 0) {
      // The first level failed: the step's failure, for the controller's policy; the levels below are not tried.
      text << "the step's QP (priority " << L.priority << ") failed";
      for (std::size_t k = 1; k < levels_.size(); ++k) {
        LevelInfo& below = info_[k];
        not_run(below);
        TextSink(below.diagnosis) << "skipped: priority " << L.priority << " failed";
      }
      return nullptr;
    }
    if (answer == nullptr) {
      describe_level(static_cast<int>(l), text);
      text << " not solved: " << to_string(S.result.info.status) << ": " << S.result.info.diagnosis;
      if (L.has_ls) {
        S.engine->describe_singular_rows(S.qp, text);
        text << "; in least squares too: " << to_string(S.ls_result.info.status) << ": " << note_;
      }
      text << "; the step keeps the answer of the levels above";
      skip = 1;
      continue;
    }
    x_ = answer->x.head(n_);
    level.task_error = task_error(static_cast<int>(l), data, x_);
    if (l + 1 == levels_.size()) break;  // nothing below to hold it for
    hold(static_cast<int>(l), data, x_);
    if (obj_w_ != QpBuilder::WrittenW::kNone || held_eq_ >= n_) {
      skip = 0;
      decided_by = static_cast<int>(l);
    }
  }
  info.iterations = 0;
  for (const LevelInfo& level : info_) info.iterations += level.iterations;
  return &x_;
}

}  // namespace redres
