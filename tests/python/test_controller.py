"""redres.Controller from Python: a caller's own Euler loop over Controller.step reproduces scenario.run() bit for
bit, a controller built from typed plugin configurations meets its task rows, and failures are statuses."""

import re

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
    # The certificate's figures: the rows' miss, computed here from the QP, and both residuals within the limits.
    miss = np.max(np.abs(qp["J"] @ theta_dot - qp["d"]))
    assert abs(info.primal_residual - miss) <= 1e-12 and info.primal_residual <= 1e-10 + 1e-9 * np.max(np.abs(qp["d"]))
    assert 0.0 <= info.dual_residual <= 1e-8 and info.complementarity == 0.0


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


# The scenario files' schemes, written as typed configurations: the same plugins in the same order (a scenario adds
# the robot file's acceleration and jerk limits after its own constraints when it lists none; a Python controller
# adds nothing, so they are listed here).
def panda_tool_elbow_posture_scheme():
    return dict(
        tasks=[redres.tasks.Frame(name="tool", frame="end_effector", reference="path", gain=8.0, priority=0),
               redres.tasks.Frame(name="elbow", frame="panda_joint4", rows=["z"], mode="inequality", lower=[0.5],
                                  gain=4.0, priority=1),
               redres.tasks.Posture(name="posture", mode="soft", gain=1.0, priority=2)],
        objectives=[redres.objectives.MinVelocityNorm(weight=0.01, priority=2)],
        constraints=[redres.constraints.JointAngleMargin(kappa=4.0, margin=0.05),
                     redres.constraints.JointVelocityLimits(), redres.constraints.JointAccelerationLimits(),
                     redres.constraints.JointJerkLimits()],
        path=redres.paths.Circle(radius=0.15, normal=[0.0, 1.0, 0.0], start_angle_deg=0))


def iiwa_pose_manipulability_levels_scheme():
    return dict(
        tasks=[redres.tasks.Frame(name="pose", frame="end_effector", rows=["x", "y", "z", "wx", "wy", "wz"],
                                  reference="path", gain=8.0, priority=0)],
        objectives=[redres.objectives.MinVelocityNorm(priority=1),
                    redres.objectives.Manipulability(measure="log_det", schedule="smoothstep", ramp_fraction=0.1,
                                                     p=0.5, priority=1)],
        constraints=[redres.constraints.JointAngleMargin(kappa=4.0, margin=0.05),
                     redres.constraints.JointVelocityLimits()],
        path=redres.paths.Circle(radius=0.06, normal=[0.0, 0.0, 1.0], timing="cycloidal"))


@pytest.mark.parametrize("config, scheme, levels", [
    ("configs/panda_tool_elbow_posture.toml", panda_tool_elbow_posture_scheme, [0, 1, 2]),
    ("configs/iiwa_pose_manipulability_levels.toml", iiwa_pose_manipulability_levels_scheme, [0, 1]),
])
def test_a_controller_with_tasks_from_python_steps_as_the_scenarios_controller(config, scheme, levels):
    s = redres.Scenario.load(source(config))
    theirs = redres.Controller.from_scenario(s)
    ours = redres.Controller(s.robot, engine="newton", T=s.duration, tau=s.step, theta0=s.theta0, **scheme())
    assert "tasks" in repr(ours)
    theta = s.theta0.copy()
    for k in range(150):
        t = k * s.step
        want, want_info = theirs.step(theta, t)
        got, got_info = ours.step(theta, t)
        assert want_info.ok, want_info.diagnosis
        assert [level.priority for level in got_info.levels] == levels
        assert [level.status for level in got_info.levels] == [level.status for level in want_info.levels]
        assert got.tolist() == want.tolist(), (k, got - want)  # bit for bit
        assert ours.r_d.tolist() == theirs.r_d.tolist()
        theta = theta + s.step * want


def test_the_python_controller_forwards_every_keyword_of_the_cpp_one():
    # The binding's signature is the first line of its docstring: every parameter it takes is one of the Python
    # class's, so none is dropped on the way (and none is added that C++ would not take).
    first = redres._redres.Controller.__init__.__doc__.splitlines()[0]
    cpp = re.findall(r"(?:\(|, )(\w+): ", first)[1:]  # (self: ..., robot: ..., ...; a type may hold ", ")
    assert cpp[:3] == ["robot", "objectives", "constraints"], first
    python = list(__import__("inspect").signature(redres.Controller.__init__).parameters)[1:]
    assert sorted(cpp) == sorted(python)
    assert {"tasks", "level", "regularization", "orientation_turn"} <= set(python)


def test_tasks_level_and_regularization_reach_the_scheme():
    robot = redres.Robot.load(source("robots/franka_panda.toml"))
    theta = robot.home.copy()
    common = dict(objectives=[redres.objectives.MinVelocityNorm()], T=1.0, tau=0.01)
    # One soft posture task at priority 1 below the hand: two levels.
    ctrl = redres.Controller(robot, tasks=[redres.tasks.Frame(frame="end_effector", reference="path"),
                                           redres.tasks.Posture(mode="soft", priority=1)],
                             path=redres.paths.Circle(radius=0.05), **common)
    _, info = ctrl.step(theta, 0.0)
    assert info.ok and [level.priority for level in info.levels] == [0, 1], info.diagnosis
    # A Python objective takes a priority too.
    class Centering(redres.Objective):
        kinematics = "position"

        def contribute(self, ctx, qp):
            qp.add_linear(ctx.theta - robot.home)
    ctrl = redres.Controller(robot, objectives=[redres.objectives.MinVelocityNorm(), Centering(priority=1)],
                             constraints=[redres.constraints.TaskTracking()], T=1.0, tau=0.01)
    _, info = ctrl.step(theta, 0.0, robot.kinematics(theta).f, np.zeros(3))
    assert info.ok and [level.priority for level in info.levels] == [0, 1], info.diagnosis
    # The acceleration level is built (it steps with r_d_ddot).
    with pytest.raises(ValueError, match="does not work at the acceleration level"):
        redres.Controller(robot, constraints=[redres.constraints.TaskTracking()], level="acceleration", **common)
    ctrl = redres.Controller(robot, objectives=[redres.objectives.MinAccelerationNorm()],
                             constraints=[redres.constraints.TaskTracking()], level="acceleration", T=1.0, tau=0.01)
    k = robot.kinematics(theta)
    _, info = ctrl.step(theta, 0.0, k.f, np.zeros(3), np.zeros(3))
    assert info.ok, info.diagnosis
    with pytest.raises(ValueError, match=r"regularization: expected a number in \(0, 1\]"):
        redres.Controller(robot, regularization=0.0, **common)
    with pytest.raises(ValueError, match="orientation_turn of a spatial robot has 3 entries"):
        redres.Controller(robot, orientation_turn=[0.1, 0.2], **common)


def test_a_configuration_in_the_wrong_list_is_named():
    robot = redres.Robot.load(source("robots/franka_panda.toml"))
    with pytest.raises(TypeError, match=r"tasks\[0\] is redres.objectives.MinVelocityNorm\(\) \(kind 'objective'\); "
                                        r"expected a redres.tasks.\* configuration"):
        redres.Controller(robot, tasks=[redres.objectives.MinVelocityNorm()])
    with pytest.raises(TypeError, match=r"objectives\[1\] is redres.tasks.Posture\(\) \(kind 'task'\)"):
        redres.Controller(robot, objectives=[redres.objectives.MinVelocityNorm(), redres.tasks.Posture()])
    with pytest.raises(redres.ConfigError, match="key 'lower'"):
        redres.Controller(robot, objectives=[redres.objectives.MinVelocityNorm()],
                          tasks=[redres.tasks.Frame(frame="end_effector", rows=["z"], lower=[0.5])])
