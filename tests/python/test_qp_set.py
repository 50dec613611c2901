"""Every engine against an independent solver, on the QPs of the shipped robots' own runs; and the cascade's
priorities held at the default tolerance.

The set: every priority level's QP (`Controller.level_qp`) at every 8th of the first 160 steps of shipped scenarios
(6- and 7-joint arms, the planar 4R, a 28-joint chain at three levels and a humanoid's waist and arm with a level that
cannot be met; soft tasks and damping give a dense W with eigenvalues down to 1e-9;
obstacle rows; levels that hold the levels above them). The reference: Debian's CVXOPT (an interior-point solver
nobody in this project wrote), polished by solving the KKT system of the active set it finds. Each engine solves each
QP from a cold start (`redres.solve_qp`). Checked: an answer called `solved` passes an independent KKT check written
here from the QP, and its objective is not above the reference's beyond the tolerance; `newton` certifies every QP
and lands on the reference's x. The per-engine figures are printed (pytest -s)."""

import numpy as np
import pytest

import redres
from conftest import source

cvxopt = pytest.importorskip("cvxopt", reason="Debian's python3-cvxopt (scripts/install_deps.sh installs it)")

CONFIGS = [
    "panda_conflict_tool_first",
    "panda_conflict_elbow_first",
    "panda_tool_elbow_posture",
    "iiwa_pose_manipulability_levels",
    "iiwa_pose_manipulability",
    "kinova_gen3_tool_axis",
    "xarm6_circle_obstacle",
    "panda_table_pole",
    "paper_r_tvcmm",
    "planar_4link_circle",
    "../tests/data/scenarios/chain28_three",  # 28 joints, three levels
    "../tests/data/scenarios/humanoid29_three",  # a humanoid's waist and arm, the middle level relaxed (least squares)
]
TOLERANCE = 1e-9  # the engines' absolute limit; the certificate's relative one is 1e-9 too


def collect():
    qps = []
    for name in CONFIGS:
        s = redres.Scenario.load(source(f"configs/{name}.toml"))
        ctrl = redres.Controller.from_scenario(s)
        theta = s.theta0.copy()
        for k in range(160):
            theta_dot, info = ctrl.step(theta, k * s.step)
            if k % 8 == 0:
                for level in range(max(1, len(info.levels))):
                    qps.append((f"{name}@{k}/{level}", ctrl.level_qp(level)))
            theta = theta + s.step * theta_dot
    return qps


def objective(qp, x):
    return 0.5 * x @ qp["W"] @ x + qp["zeta"] @ x


def kkt_residual(qp, x, y, z):
    """The largest KKT violation of (x, y, z), from the QP alone: rows, bounds, the signs and complementarity of the
    inequality rows' multipliers, and stationarity with the bounds' multipliers taken from the gradient where a bound
    is active (within 1e-9 of it, relative), each relative to the size of what it compares."""
    W, zeta, J, d, A, b, lo, hi = (qp[k] for k in ("W", "zeta", "J", "d", "A", "b", "lo", "hi"))
    primal = max([0.0] + list(np.abs(J @ x - d)) + list(A @ x - b) + list(lo - x) + list(x - hi))
    g = W @ x + zeta - J.T @ y + A.T @ z
    scale = 1.0 + max(np.max(np.abs(W @ x)), np.max(np.abs(zeta)), np.max(np.abs(J.T @ y), initial=0.0))
    near = 1e-9 * (1.0 + np.abs(x))
    at_lo, at_hi = x - lo <= near, hi - x <= near
    stationarity = np.where(at_lo & at_hi, 0.0, np.where(at_lo, np.maximum(-g, 0.0),
                                                         np.where(at_hi, np.maximum(g, 0.0), np.abs(g))))
    slack = b - A @ x
    rows = np.abs(np.minimum(z, slack)) if len(z) else np.zeros(0)
    return primal / (1.0 + np.max(np.abs(d), initial=0.0)), max(np.max(stationarity) / scale,
                                                                 np.max(rows, initial=0.0))


def reference(qp):
    """CVXOPT's answer, polished on its active set; None where CVXOPT cannot take the QP (rows of J dependent)."""
    W, zeta, J, d, A, b, lo, hi = (qp[k] for k in ("W", "zeta", "J", "d", "A", "b", "lo", "hi"))
    n = len(zeta)
    G = np.vstack([A, np.eye(n), -np.eye(n)])
    h = np.concatenate([b, hi, -lo])
    m = cvxopt.matrix
    cvxopt.solvers.options.update({"show_progress": False, "abstol": 1e-12, "reltol": 1e-12, "feastol": 1e-12,
                                   "maxiters": 200})
    try:
        sol = cvxopt.solvers.qp(m(W), m(zeta), m(G), m(h), m(J) if len(d) else None, m(d) if len(d) else None)
    except ValueError:
        return None
    if sol["status"] != "optimal" and sol["gap"] is not None and sol["gap"] > 1e-8:
        return None
    x = np.array(sol["x"]).ravel()
    # Polish: the active bounds fixed, the active inequality rows as equalities, the KKT system solved exactly.
    free = ~((x - lo <= 1e-7) | (hi - x <= 1e-7))
    fixed = np.where(x - lo <= 1e-7, lo, hi)
    rows = np.abs(A @ x - b) <= 1e-7
    E = np.vstack([J, A[rows]])
    e = np.concatenate([d, b[rows]])
    Wf = W[np.ix_(free, free)]
    K = np.block([[Wf, -E[:, free].T], [E[:, free], np.zeros((E.shape[0], E.shape[0]))]])
    rhs = np.concatenate([-(zeta[free] + W[np.ix_(free, ~free)] @ fixed[~free]), e - E[:, ~free] @ fixed[~free]])
    u, *_ = np.linalg.lstsq(K, rhs, rcond=None)
    polished = np.where(free, 0.0, fixed)
    polished[free] = u[: free.sum()]
    inside = np.all(polished >= lo - 1e-12) and np.all(polished <= hi + 1e-12) and np.all(A @ polished <= b + 1e-12)
    if inside and objective(qp, polished) <= objective(qp, x) + 1e-12 and np.max(np.abs(J @ polished - d),
                                                                                  initial=0.0) <= 1e-10:
        return polished
    return x


@pytest.fixture(scope="module")
def qp_set():
    qps = collect()
    refs = [(name, qp, reference(qp)) for name, qp in qps]
    return [(name, qp, x) for name, qp, x in refs if x is not None], len(qps)


def test_the_set_holds_dense_and_ill_conditioned_qps(qp_set):
    qps, total = qp_set
    dense = [q for _, q, _ in qps if np.max(np.abs(q["W"] - np.diag(np.diag(q["W"])))) > 0.0]
    smallest = min(np.linalg.eigvalsh(q["W"])[0] for _, q, _ in qps)
    print(f"\nQP set: {total} QPs, {len(qps)} with a reference, {len(dense)} with a dense W, smallest eigenvalue "
          f"{smallest:.2g}")
    assert len(qps) >= 0.9 * total
    assert len(dense) >= 40 and smallest <= 1e-8
    assert any(len(q["b"]) > 0 for _, q, _ in qps)


@pytest.mark.parametrize("engine", ["newton", "projection", "nlopt"])
def test_every_solved_answer_is_right(qp_set, engine):
    qps, _ = qp_set
    solved, errors, gaps, conditioned = 0, [], [], []
    for name, qp, x_ref in qps:
        r = redres.solve_qp(qp, engine, tolerance=TOLERANCE, max_iterations=200000)
        if r["status"] != "solved":
            continue
        solved += 1
        x = r["x"]
        primal, dual = kkt_residual(qp, x, r["y"], r["z"])
        assert primal <= 1e-8 and dual <= 1e-7, f"{engine} on {name}: primal {primal:.3g}, dual {dual:.3g}"
        gap = objective(qp, x) - objective(qp, x_ref)
        assert gap <= 1e-7 * (1.0 + abs(objective(qp, x_ref))), f"{engine} on {name}: objective {gap:.3g} above"
        errors.append(np.max(np.abs(x - x_ref)))
        gaps.append(gap)
        if np.linalg.eigvalsh(qp["W"])[0] >= 1e-6:  # x is determined to about the residual / the eigenvalue
            conditioned.append(errors[-1])
    share = solved / len(qps)
    print(f"\n{engine}: certified {solved} of {len(qps)} ({100 * share:.1f} %); x error against the reference: "
          f"largest {np.max(conditioned):.2g} where W's smallest eigenvalue >= 1e-6 ({len(conditioned)} QPs), "
          f"largest {np.max(errors):.2g} over all (W down to 1e-9 leaves x loosely determined); objective above the "
          f"reference by at most {max(gaps):.2g}")
    if engine == "newton":
        assert solved == len(qps)
        assert np.max(conditioned) <= 1e-6


def test_a_lower_level_never_gains_what_a_higher_one_loses():
    """configs/panda_tool_elbow_posture.toml with the elbow's level asking for more than it can have (lower = 0.8):
    the priority-0 tool rows, which the first level meets exactly, stay met at the step's answer to 1e-9 (the levels
    below hold them at 1e-4 of the tolerance; at the tolerance itself they slipped by 5e-7 m/s)."""
    s = redres.Scenario.load(source("configs/panda_tool_elbow_posture.toml"), overrides={"tasks.1.lower": [0.8]})
    ctrl = redres.Controller.from_scenario(s)
    theta = s.theta0.copy()
    worst, relaxed = 0.0, 0
    for k in range(s.steps + 1):
        theta_dot, info = ctrl.step(theta, min(k * s.step, s.duration))
        first = ctrl.level_qp(0)
        assert info.levels[0].status == "solved", info.diagnosis
        relaxed += info.levels[1].status == "relaxed"
        worst = max(worst, np.max(np.abs(first["J"] @ theta_dot - first["d"])))
        theta = theta + s.step * theta_dot
    print(f"\npriority 0 held to {worst:.2g} over {s.steps + 1} steps; level 1 relaxed on {relaxed}")
    assert relaxed > 0  # the case is exercised: level 1 cannot be met
    assert worst <= 1e-9


def test_a_level_its_engine_cannot_solve_is_tried_by_newton_before_least_squares():
    """projection with 5 iterations per solve: where the first level still gets solved, a lower level that
    projection leaves at its iteration cap is solved by newton (before it would be relaxed into least squares)."""
    s = redres.Scenario.load(source("configs/panda_tool_elbow_posture.toml"),
                             overrides={"solver.engine": "projection", "solver.max_iterations": 5})
    ctrl = redres.Controller.from_scenario(s)
    theta = s.theta0.copy()
    by_newton = 0
    for k in range(200):
        theta_dot, info = ctrl.step(theta, k * s.step)
        if info.levels[0].status == "solved":
            assert all(level.status == "solved" for level in info.levels), [l.diagnosis for l in info.levels]
            by_newton += sum("max_iterations with projection, solved by newton" in level.diagnosis
                             for level in info.levels[1:])
        theta = theta + s.step * theta_dot
    assert by_newton >= 1


def chain_run(which, robot="chain28"):
    s = redres.Scenario.load(source(f"tests/data/scenarios/{robot}_{which}.toml"))
    r = s.run()
    theta_dot = np.column_stack([r[f"theta_dot_{j}"] for j in range(1, s.robot.dof + 1)])
    return r, theta_dot


def test_three_levels_on_a_long_chain_meet_priority_0_without_chatter():
    """A 28-joint chain set up as docs/tasks.md advises (the right hand's pose at priority 0, the left hand held at 1,
    soft posture and velocity norm at 2): every level solved at every step, no joint velocity jumps between steps
    (largest change 0.01 rad/s per 5 ms step, where the one-level run's is 0.002), and priority 0 tracked as closely
    as by the one-level run. The step's cost against one level is BM_ChainLevels' (benchmarks)."""
    one, v1 = chain_run("one")
    three, v3 = chain_run("three")
    assert one.failures == 0 and three.failures == 0, three.first_failure
    for level in range(3):
        assert np.all(three[f"level_{level}_status"] == 0), f"level {level}"
    jump1 = np.max(np.abs(np.diff(v1, axis=0)))
    jump3 = np.max(np.abs(np.diff(v3, axis=0)))
    err1, err3 = np.max(one["position_error"]), np.max(three["position_error"])
    print(f"\nchain28: largest joint-velocity change per step {jump3:.3g} rad/s (one level {jump1:.3g}); "
          f"priority-0 position error {err3:.3g} m (one level {err1:.3g})")
    assert jump3 <= 0.01
    assert err3 <= 1.5 * err1


def test_three_levels_on_a_humanoid_with_a_level_that_cannot_be_met():
    """tests/data/scenarios/humanoid29_three.toml, set up as docs/tasks.md advises: a 29-joint humanoid's right hand at
    priority 0, its left hand (a side branch that only the 3 waist joints move, about one point: the hand's distance
    from it cannot change) sent to a target at 1, a soft posture and the velocity norm at 2. Level 1 cannot be met and
    is relaxed at every step; priority 0 is tracked as by the one-level run; no joint velocity jumps between steps
    (the issue's humanoid jumped between its bounds, 3.7 rad/s, 483 times). The step's cost against one level is
    BM_HumanoidLevels' (benchmarks)."""
    one, v1 = chain_run("one", "humanoid29")
    three, v3 = chain_run("three", "humanoid29")
    assert one.failures == 0 and three.failures == 0, three.first_failure
    assert np.all(three["level_0_status"] == 0) and np.all(three["level_2_status"] == 0)
    assert np.all(three["level_1_status"] == 6)  # relaxed: solved in least squares
    jump1 = np.max(np.abs(np.diff(v1, axis=0)))
    jump3 = np.max(np.abs(np.diff(v3, axis=0)))
    err1, err3 = np.max(one["position_error"]), np.max(three["position_error"])
    left = three["left_error"]
    print(f"\nhumanoid29: largest joint-velocity change per step {jump3:.3g} rad/s (one level {jump1:.3g}); "
          f"priority-0 position error {err3:.3g} m (one level {err1:.3g}); left hand {left[0]:.3g} -> {left[-1]:.3g} m")
    assert jump3 <= 0.02
    assert err3 <= 1.1 * err1
    assert left[-1] < 0.5 * left[0]  # the relaxed level still moves the left hand as far towards its target as it can


@pytest.mark.parametrize("posture_priority", [2, 1])
def test_a_level_relaxed_at_the_last_step_gets_the_answer_a_fresh_controller_gives(posture_priority):
    """A level relaxed at the last step is solved in least squares first, and exactly only once that meets its rows
    (Cascade::solve_levels). The left hand of humanoid29_three on two rows it can meet, at a gain its velocity bounds
    cannot follow at first: relaxed for the first steps, then solved. At every step the answer is the one a new
    controller (which tries the exact QP first) gives at the same state, and the statuses agree. With the soft
    posture at the left hand's level, the least squares is no fit of its rows alone, and the level takes the exact QP
    first at every step (the same answers again). (Level 2's newton can
    stall a few ulps short of its target, 1e-4 of the tolerance, warm or cold; on such a step the two answers are
    those of different levels and are not compared: the note of issue 42 counts them.)"""
    overrides = {"tasks.1.gain": 100.0, "tasks.1.rows": ["x", "y"], "tasks.1.position": [0.38, 0.38, 0.2576],
                 "tasks.2.priority": posture_priority}
    path = source("tests/data/scenarios/humanoid29_three.toml")
    s = redres.Scenario.load(path, overrides=overrides)
    ctrl = redres.Controller.from_scenario(s)
    theta = s.theta0.copy()
    statuses, worst, compared = [], 0.0, 0
    for k in range(40):
        t = k * s.step
        theta_dot, info = ctrl.step(theta, t)
        fresh = redres.Controller.from_scenario(redres.Scenario.load(path, overrides=overrides))
        fresh_dot, fresh_info = fresh.step(theta, t)
        mine, theirs = [level.status for level in info.levels], [level.status for level in fresh_info.levels]
        assert mine[:2] == theirs[:2], k
        if mine == theirs:
            compared += 1
            worst = max(worst, np.max(np.abs(theta_dot - fresh_dot)))
        statuses.append(info.levels[1].status)
        theta = theta + s.step * theta_dot
    relaxed = statuses.count("relaxed")
    print(f"\nlevel 1 relaxed on the first {relaxed} steps, then solved; largest difference from a new controller "
          f"{worst:.2g} rad/s on the {compared} of 40 steps where every level's status agrees")
    assert relaxed >= 2 and statuses == ["relaxed"] * relaxed + ["solved"] * (40 - relaxed)
    if posture_priority == 2:
        assert relaxed < 40  # back to the exact QP once the rows can be met (the posture at 1 slows the hand down)
    assert compared >= 30 and worst <= 1e-8
