#include "redres/qp/qp.hpp"

#include <cmath>
#include <sstream>

#include "redres/common/error.hpp"
#include "redres/common/hot.hpp"

namespace redres {

void QpProblem::resize(int n, int m_e, int m_i) {
  REDRES_REQUIRE(n > 0 && m_e >= 0 && m_i >= 0, "QpProblem::resize", "n > 0, m_e >= 0 and m_i >= 0");
  W.setZero(n, n);
  zeta.resize(n);
  J.resize(m_e, n);
  d.resize(m_e);
  A.resize(m_i, n);
  b.resize(m_i);
  lo.resize(n);
  hi.resize(n);
  lo_source.assign(static_cast<std::size_t>(n), -1);
  hi_source.assign(static_cast<std::size_t>(n), -1);
  eq_source.assign(static_cast<std::size_t>(m_e), -1);
  in_source.assign(static_cast<std::size_t>(m_i), -1);
  clear();
}

REDRES_HOT void QpProblem::clear() {
  if (w_diagonal) {
    // Only the diagonal can be non-zero (the flag's invariant): zero it alone.
    const Eigen::Index nn = W.rows();
    double* w = W.data();
    for (Eigen::Index i = 0; i < nn; ++i) w[i * (nn + 1)] = 0.0;
  } else {
    W.setZero();
  }
  zeta.setZero();
  J.setZero();
  d.setZero();
  A.setZero();
  b.setZero();
  // The sources stay: a bound that a plugin tightens gets its source then, and an open one has none to show.
  lo.setConstant(-kNoBound);
  hi.setConstant(kNoBound);
  w_diagonal = true;
}

namespace {

template <class M>
void check_finite(const M& m, const char* what) {
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      if (!std::isfinite(m(r, c))) {
        std::ostringstream s;
        s << what << "(" << r << (m.cols() > 1 ? ", " + std::to_string(c) : std::string()) << ") is finite (got "
          << m(r, c) << ")";
        throw_invalid_argument("QpProblem", s.str());
      }
    }
  }
}
}  // namespace

void QpProblem::validate() const {
  const Eigen::Index nn = zeta.size();
  REDRES_REQUIRE(W.rows() == nn && W.cols() == nn, "QpProblem", "W is n x n");
  REDRES_REQUIRE(J.cols() == nn && J.rows() == d.size(), "QpProblem", "J is m_e x n and d has m_e entries");
  REDRES_REQUIRE(A.cols() == nn && A.rows() == b.size(), "QpProblem", "A is m_i x n and b has m_i entries");
  REDRES_REQUIRE(lo.size() == nn && hi.size() == nn, "QpProblem", "lo and hi have n entries");
  // Fast check first (finite_probe); the entry-by-entry search that names the culprit runs only on failure.
  const auto probe = [](const auto& m) { return finite_probe(m.data(), m.size()); };
  if (!(probe(W) + probe(zeta) + probe(J) + probe(d) + probe(A) + probe(b) == 0.0)) {
    check_finite(W, "W");
    check_finite(zeta, "zeta");
    check_finite(J, "J");
    check_finite(d, "d");
    check_finite(A, "A");
    check_finite(b, "b");
  }
  // Bounds may be infinite, not NaN.
  if (lo.hasNaN() || hi.hasNaN()) {
    for (Eigen::Index i = 0; i < nn; ++i) {
      REDRES_REQUIRE(!std::isnan(lo(i)) && !std::isnan(hi(i)), "QpProblem",
                     "lo(" + std::to_string(i) + ") and hi(" + std::to_string(i) + ") are not NaN");
    }
  }
}

BoundConflict find_bound_conflict(const QpProblem& qp) {
  BoundConflict c;
  for (int i = 0; i < qp.n(); ++i) {
    if (qp.lo(i) > qp.hi(i)) {
      c.joint = i;
      c.lo = qp.lo(i);
      c.hi = qp.hi(i);
      c.lo_source = source_name(qp, qp.lo_source[static_cast<std::size_t>(i)]);
      c.hi_source = source_name(qp, qp.hi_source[static_cast<std::size_t>(i)]);
      return c;
    }
  }
  return c;
}

std::string_view source_name(const QpProblem& qp, int s) {
  return s >= 0 && s < static_cast<int>(qp.source_names.size())
             ? std::string_view(qp.source_names[static_cast<std::size_t>(s)])
             : std::string_view("(none)");
}

void describe(const BoundConflict& c, const std::vector<std::string>& joint_names, TextSink& s) {
  if (c.joint < 0) {
    s << "no bound conflict";
    return;
  }
  s.precision(9);
  s << "joint " << c.joint + 1;
  if (c.joint < static_cast<int>(joint_names.size()))
    s << " ('" << joint_names[static_cast<std::size_t>(c.joint)] << "')";
  s << ": lower bound " << c.lo << " (from '" << c.lo_source << "') > upper bound " << c.hi << " (from '" << c.hi_source
    << "')";
}

std::string describe(const BoundConflict& c, const std::vector<std::string>& joint_names) {
  return text_of([&](TextSink& s) { describe(c, joint_names, s); });
}

}  // namespace redres
