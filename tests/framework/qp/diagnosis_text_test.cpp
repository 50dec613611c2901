// The text of a failed step's diagnosis, written into storage reserved at setup: with many rows missed, the rows
// missed by most are named (at most 8) and the rest counted, so the joints held at a bound still fit; and a diagnosis
// string that lost its reserve (assigned from a small temporary) gets it back rather than cutting later texts.

#include <string>

#include <gtest/gtest.h>

#include "redres/control/engine_registry.hpp"
#include "redres/qp/lvi.hpp"

namespace redres {
namespace {

// One joint in [-1, 1] and `rows` inequality rows x <= -(2 + r): none can be met; row r is missed by 1 + r at best.
QpProblem unmeetable(int rows) {
  QpProblem qp;
  qp.resize(1, 0, rows);
  qp.W(0, 0) = 1.0;
  qp.lo(0) = -1.0;
  qp.hi(0) = 1.0;
  for (int r = 0; r < rows; ++r) {
    qp.A(r, 0) = 1.0;
    qp.b(r) = -(2.0 + r);
  }
  qp.source_names = {"the_rows"};
  qp.variable_names = {"j1"};
  qp.lo_source = {0};
  qp.hi_source = {0};
  qp.in_source.assign(static_cast<std::size_t>(rows), 0);
  return qp;
}

TEST(DiagnosisText, ManyMissedRowsAreCountedAndTheJointsStillFit) {
  for (const char* name : {"newton", "projection"}) {
    SCOPED_TRACE(name);
    const QpProblem qp = unmeetable(30);
    auto engine = make_engine(name);
    SolverResult r;
    engine->setup(1, 0, 30, r);
    engine->solve(qp, r);
    ASSERT_EQ(r.info.status, SolverStatus::kInfeasible) << r.info.diagnosis;
    const std::string& d = r.info.diagnosis;
    EXPECT_NE(d.find("inequality row 30 "), std::string::npos) << "the row missed by most is named: " << d;
    EXPECT_EQ(d.find("inequality row 1 "), std::string::npos) << "the row missed by least is counted: " << d;
    EXPECT_NE(d.find("and 22 more rows missed by less"), std::string::npos) << d;
    EXPECT_NE(d.find("joints held at a bound there: joint 1 ('j1') at its lower bound -1"), std::string::npos) << d;
    EXPECT_EQ(d.find("[...]"), std::string::npos) << "nothing cut: " << d;
    EXPECT_GE(r.info.diagnosis.capacity(), kDiagnosisCapacity);
  }
}

TEST(DiagnosisText, AStringThatLostItsReserveGetsItBack) {
  const QpProblem qp = unmeetable(3);
  auto engine = make_engine("newton");
  SolverResult r;
  engine->setup(1, 0, 3, r);
  r.info.diagnosis = std::string("short");  // a caller's assignment: the reserve is gone
  r.info.diagnosis.shrink_to_fit();
  engine->solve(qp, r);
  EXPECT_GE(r.info.diagnosis.capacity(), kDiagnosisCapacity);
  EXPECT_NE(r.info.diagnosis.find("joints held at a bound there"), std::string::npos) << r.info.diagnosis;
}

}  // namespace
}  // namespace redres
