"""redres.Controller from Python: a caller's own Euler loop over Controller.step reproduces scenario.run() bit for
bit, a controller built from typed plugin configurations meets its task rows, and failures are statuses."""

import numpy as np
import pytest

import redres
from conftest import source


def test_a_python_loop_over_step_reproduces_the_run_bit_for_bit():
    s = redres.Scenario.load(source("configs/paper_r_tvcmm.toml"))
    ctrl = redres.Controller.from_scenario(s)
    theta = s.theta0.copy()
    for k in range(s.steps + 1):
        t = s.duration if k == s.steps else k * s.step
        theta_dot, info = ctrl.step(theta, t)
        assert info.ok, info.diagnosis
        if k < s.steps:
            theta = theta + s.step * theta_dot
    # The run records theta(T) after the last step without integrating it.
    assert theta.tolist() == s.run().final_theta.tolist()


def test_a_controller_from_typed_configs_meets_its_task_rows():
    robot = redres.Robot.load(source("robots/franka_panda.toml"))
    ctrl = redres.Controller(
        robot,
        objectives=[redres.objectives.MinVelocityNorm(), redres.objectives.Manipulability(p=0.5, measure="log_det")],
        constraints=[redres.constraints.TaskTracking(gain=8.0), redres.constraints.JointVelocityLimits(),
                     redres.constraints.JointAngleMargin()],
        engine=redres.engines.Newton(tolerance=1e-10), T=5.0, tau=0.01)
    theta = robot.home.copy()
    k = robot.kinematics(theta)
    r_d = k.f + np.array([0.01, -0.005, 0.002])
    r_d_dot = np.array([0.02, 0.0, -0.01])
    theta_dot, info = ctrl.step(theta, 0.5, r_d, r_d_dot)
    assert info.ok and info.engine == "newton", info.diagnosis
    assert theta_dot.shape == (7,) and theta_dot.dtype == np.float64
    # J theta_dot = r_d_dot + K (r_d - f), the task rows (eq. 6).
    assert np.allclose(k.J @ theta_dot, r_d_dot + 8.0 * (r_d - k.f), atol=1e-9)
    lo, hi = robot.velocity_limits(theta)
    assert np.all(theta_dot >= lo) and np.all(theta_dot <= hi)
    qp = ctrl.qp
    assert qp["W"].shape == (7, 7) and qp["J"].shape == (3, 7)
    assert np.array_equal(ctrl.f, k.f)


def test_a_path_is_placed_at_the_start_and_followed():
    robot = redres.Robot.load(source("robots/franka_panda.toml"))
    T, tau = 2.0, 0.01
    ctrl = redres.Controller(robot, objectives=[redres.objectives.MinVelocityNorm()],
                             constraints=[redres.constraints.TaskTracking(gain=8.0)],
                             path=redres.paths.Circle(radius=0.03), T=T, tau=tau, theta0=robot.home)
    theta = robot.home.copy()
    worst = 0.0
    for k in range(int(T / tau) + 1):
        theta_dot, info = ctrl.step(theta, k * tau)
        assert info.ok
        worst = max(worst, np.linalg.norm(ctrl.r_d - ctrl.f))
        theta = theta + tau * theta_dot
    assert np.allclose(ctrl.r_d, robot.kinematics(robot.home).f, atol=1e-12), "a circle ends where it starts"
    assert worst < 1e-3


def test_a_step_that_does_not_solve_is_a_status_with_a_diagnosis():
    robot = redres.Robot.load(source("robots/paper_pushrod_6dof.toml"))
    ctrl = redres.Controller(robot, objectives=[redres.objectives.MinVelocityNorm()],
                             constraints=[redres.constraints.TaskTracking(), redres.constraints.JointVelocityLimits()],
                             engine="projection", T=10.0, tau=0.01)
    theta = robot.home.copy()
    f = robot.kinematics(theta).f
    # A desired velocity of 100 m/s: beyond the velocity limits, the rows cannot be met.
    theta_dot, info = ctrl.step(theta, 0.0, f, np.array([100.0, 0.0]))
    assert not info.ok
    assert info.status in ("infeasible", "max_iterations")
    assert info.diagnosis
    assert theta_dot.shape == (6,)


def test_wrong_sizes_raise_with_the_condition():
    robot = redres.Robot.load(source("robots/paper_pushrod_6dof.toml"))
    ctrl = redres.Controller(robot, objectives=[redres.objectives.MinVelocityNorm()],
                             constraints=[redres.constraints.TaskTracking()], T=10.0, tau=0.01)
    with pytest.raises(ValueError, match="reference_dim"):
        ctrl.step(robot.home, 0.0, np.zeros(3), np.zeros(3))
    with pytest.raises(ValueError):
        ctrl.step(np.zeros(4), 0.0, np.zeros(2), np.zeros(2))
    with pytest.raises(ValueError, match="per joint|entries|joint"):
        redres.Controller(robot, objectives=[], constraints=[redres.constraints.JointAngleMargin(margin=[0.1, 0.2])])


def test_a_controller_from_a_scenario_relaxes_as_the_run_does():
    # The 4R arm starting stretched: under "relax" the first steps are relaxed, not held. Controller.from_scenario
    # must carry the policy (a hand-built loop once missed it, and its steps held).
    scenario = source("tests/data/scenarios/stretched_4r.toml")
    s = redres.Scenario.load(str(scenario))
    ctrl = redres.Controller.from_scenario(s)
    assert "planar_4link" in repr(ctrl) and "engine 'newton'" in repr(ctrl) and "2 constraints" in repr(ctrl)
    statuses = []
    theta = s.theta0.copy()
    for k in range(s.steps + 1):
        theta_dot, info = ctrl.step(theta, s.duration if k == s.steps else k * s.step)
        statuses.append(info.status)
        if info.status in ("solved", "relaxed") and k < s.steps:
            theta = theta + s.step * theta_dot
    run = redres.Scenario.load(str(scenario)).run()
    assert statuses.count("relaxed") == run.summary["solver"]["relaxed_steps"] >= 1
    assert theta.tolist() == run.final_theta.tolist()


def test_the_column_groups_name_the_result_columns():
    groups = redres.trajectory_column_groups()
    assert [g["name"] for g in groups][:3] == ["t", "theta_", "theta_dot_"]
    result = redres.Scenario.load(source("configs/paper_r_fast.toml"), overrides={"duration": 0.2}).run()
    names = []
    for g in groups:
        if g["count"] == "n":
            names += [g["name"] + str(j) for j in range(1, 7)]
        elif g["count"] == "m_ref":
            names += [g["name"] + r for r in ("x", "y")]
        elif g["count"] == "1":
            names.append(g["name"])
    assert list(result.columns)[: len(names)] == names
    assert all(g["meaning"] for g in groups)


def test_a_measured_velocity_steps_within_the_pandas_acceleration_limits():
    s = redres.Scenario.load(source("configs/panda_helix_fast.toml"))
    ctrl = redres.Controller.from_scenario(s)
    limits = np.array([15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0])  # robots/franka_panda.toml
    theta = s.theta0.copy()
    velocity = np.zeros(7)
    for k in range(200):
        theta_dot, info = ctrl.step(theta, velocity, k * s.step)
        assert info.status in ("solved", "relaxed"), info.diagnosis
        # The commanded acceleration, from the previous command, within the limits.
        assert np.allclose(ctrl.theta_ddot, (theta_dot - velocity) / s.step, rtol=0, atol=1e-9)
        assert np.all(np.abs(ctrl.theta_ddot) <= limits + 1e-9)
        assert np.array_equal(ctrl.theta_dot_prev, velocity)
        theta = theta + s.step * theta_dot
        velocity = theta_dot
    # A robot with acceleration limits brakes by default and refuses to hold (a velocity jump).
    with pytest.raises(ValueError, match="velocity jump"):
        ctrl.set_failure_policy("hold")
    ctrl.set_failure_policy("brake", recover_error=0.002)
    assert ctrl.failure_policy == "brake"
    # The names are the scenario file's [solver] on_infeasible names, read by the same table.
    ctrl.set_failure_policy("relax", relax_weight=1e3)
    assert ctrl.failure_policy == "relax"
    ctrl.set_failure_policy("stop")
    assert ctrl.failure_policy == "stop"
    with pytest.raises(ValueError, match="one of 'hold', 'stop', 'relax', 'continue', 'brake', got 'halt'"):
        ctrl.set_failure_policy("halt")
    assert ctrl.failure_policy == "stop"  # a refused name changes nothing


def test_a_scheme_with_priority_levels_reports_each_level_and_keeps_the_hand_on_its_path():
    # configs/panda_tool_elbow_posture.toml: the hand (priority 0), the elbow above 0.5 m (1), the posture (2).
    s = redres.Scenario.load(source("configs/panda_tool_elbow_posture.toml"))
    ctrl = redres.Controller.from_scenario(s)
    theta = s.theta0.copy()
    for k in range(300):
        theta_dot, info = ctrl.step(theta, k * s.step)
        assert info.ok, info.diagnosis
        assert [level.priority for level in info.levels] == [0, 1, 2]
        assert all(level.status in ("solved", "relaxed") for level in info.levels), [l.diagnosis for l in info.levels]
        assert info.levels[0].task_error < 1e-6  # the hand's rows are met
        theta = theta + s.step * theta_dot
    # A one-level scheme has no levels to report.
    _, info = redres.Controller.from_scenario(redres.Scenario.load(source("configs/paper_r_tvcmm.toml"))).step(
        redres.Scenario.load(source("configs/paper_r_tvcmm.toml")).theta0, 0.0)
    assert info.levels == []
