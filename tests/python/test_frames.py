"""The robot's named frames in a Python plugin's step context (issue #29): ctx.frame_names, ctx.frame_pose(name),
ctx.frame_jacobian(name, point) and ctx.link_frames, read from the step's kinematics; checked against the task's
f, J and end-effector pose, against central differences of the robot's kinematics, and with a step whose
kinematics stop at 'position'. The same accessors on redres.Kinematics, and the errors for an unknown frame and a
wrong point."""

import numpy as np
import pytest

import redres
from conftest import source

H = 1e-5  # central differences: truncation O(H^2), rounding O(1e-16 / H)


class FrameProbe(redres.Objective):
    """Reads the frames during contribute() and keeps copies of what it read; adds x'x/2 so that the QP is whole."""
    type = "py_frame_probe"
    kinematics = "jacobian"

    def __init__(self, names=(), point=None, **kw):
        super().__init__(**kw)
        self.names = list(names)
        self.point = point
        self.seen = []

    def contribute(self, ctx, qp):
        read = {"theta": ctx.theta, "f": ctx.f, "ee_pose": ctx.ee_pose, "frame_names": ctx.frame_names,
                "link_frames": ctx.link_frames}
        if self.kinematics != "position":  # J is filled from 'jacobian' on
            read["J"] = ctx.J
        for name in self.names:
            read[name] = (ctx.frame_pose(name), ctx.frame_jacobian(name),
                          ctx.frame_jacobian(name, self.point) if self.point is not None else None)
        self.seen.append(read)
        qp.add_identity(1.0)


class PositionOnlyProbe(FrameProbe):
    type = "py_frame_probe_position"
    kinematics = "position"


class HoldStill(redres.Constraint):
    """A position-level constraint (x = 0 by bounds): with PositionOnlyProbe, a step whose kinematics stop at
    'position'."""
    type = "py_hold_still"
    kinematics = "position"

    def contribute(self, ctx, qp):
        qp.intersect_bounds(np.zeros(qp.n), np.zeros(qp.n))


def random_theta(robot, rng):
    lo, hi = robot.lower_limits, robot.upper_limits
    return lo + (hi - lo) * rng.uniform(0.1, 0.9, robot.dof)


def step_with(robot, probe, theta, constraints=None):
    if constraints is None:
        constraints = [redres.constraints.TaskTracking()]
    ctrl = redres.Controller(robot, objectives=[probe], constraints=constraints, theta0=theta)
    f = robot.kinematics(theta).f
    ctrl.step(theta, 0.0, f, np.zeros_like(f))
    assert probe.seen, "contribute() was not called"
    read = probe.seen[-1]
    assert np.array_equal(read["theta"], theta)
    return read


def point_of(pose, point):
    return pose[:3, :3] @ point + pose[:3, 3]


def angular_difference(plus, minus):
    """omega * 2h from R+ R-^T = I + 2h [omega]x + O(h^2): the vee of its antisymmetric part."""
    d = plus[:3, :3] @ minus[:3, :3].T
    a = (d - d.T) / 2
    return np.array([a[2, 1], a[0, 2], a[1, 0]])


# DH Panda: its frames are the joints' link frames (named after the joints) and "end_effector"; the URDF Panda names
# its links and has panda_link8, a frame with an offset from joint 7's link frame.
ROBOTS = {"robots/franka_panda.toml": ["panda_joint4", "end_effector"],
          "robots/franka_panda_urdf.toml": ["panda_link4", "panda_link8", "end_effector"]}


@pytest.mark.parametrize("path", sorted(ROBOTS))
def test_the_end_effector_frame_is_the_tasks_pose_and_jacobian(path):
    robot = redres.Robot.load(source(path))
    assert robot.task_dim == 3  # a position task: J is the end effector's Jv
    rng = np.random.default_rng(29)
    for _ in range(3):
        theta = random_theta(robot, rng)
        read = step_with(robot, FrameProbe(["end_effector"]), theta)
        pose, J, _ = read["end_effector"]
        assert pose.shape == (4, 4) and J.shape == (6, robot.dof)
        np.testing.assert_allclose(pose, read["ee_pose"], rtol=0, atol=1e-12)
        np.testing.assert_allclose(pose[:3, 3], read["f"][:3], rtol=0, atol=1e-12)
        np.testing.assert_allclose(J[:3], read["J"][:3], rtol=0, atol=1e-12)
        assert np.allclose(pose[3], [0, 0, 0, 1])
        assert read["frame_names"] == robot.kinematics(theta).frame_names
        assert read["frame_names"][-1] == "end_effector"
        assert all(n in read["frame_names"] for n in ROBOTS[path])


@pytest.mark.parametrize("path", sorted(ROBOTS))
def test_frame_jacobians_match_central_differences_of_the_robots_kinematics(path):
    robot = redres.Robot.load(source(path))
    names = ROBOTS[path]
    rng = np.random.default_rng(2900)
    for _ in range(3):
        theta = random_theta(robot, rng)
        point = rng.normal(scale=0.2, size=3)
        read = step_with(robot, FrameProbe(names, point=point), theta)
        delta = rng.normal(size=robot.dof)
        delta /= np.linalg.norm(delta)
        plus, minus = robot.kinematics(theta + H * delta), robot.kinematics(theta - H * delta)
        here = robot.kinematics(theta)
        for name in names:
            pose, J0, Jp = read[name]
            np.testing.assert_allclose(pose, here.frame_pose(name), rtol=0, atol=1e-12)
            for p, J in ((np.zeros(3), J0), (point, Jp)):
                v = (point_of(plus.frame_pose(name), p) - point_of(minus.frame_pose(name), p)) / (2 * H)
                np.testing.assert_allclose(J[:3] @ delta, v, rtol=0, atol=1e-6, err_msg=f"{name} at {p}")
                w = angular_difference(plus.frame_pose(name), minus.frame_pose(name)) / (2 * H)
                np.testing.assert_allclose(J[3:] @ delta, w, rtol=0, atol=1e-6, err_msg=f"{name} at {p}")
            # The same point's Jacobian, from the origin's: v_p = v_o + omega x (R p).
            r = pose[:3, :3] @ point
            np.testing.assert_allclose(Jp[:3], J0[:3] - np.cross(r, J0[3:].T).T, rtol=0, atol=1e-12)
            np.testing.assert_allclose(Jp[3:], J0[3:], rtol=0, atol=0)


def test_the_frames_need_only_position_kinematics_and_match_the_link_frames():
    robot = redres.Robot.load(source("robots/franka_panda.toml"))
    theta = random_theta(robot, np.random.default_rng(4))
    probe = PositionOnlyProbe(["panda_joint4", "end_effector"], point=np.array([0.1, -0.05, 0.2]))
    read = step_with(robot, probe, theta, constraints=[HoldStill()])
    full = robot.kinematics(theta)  # computed at 'all'
    assert len(read["link_frames"]) == robot.dof
    for mine, theirs in zip(read["link_frames"], full.link_frames):
        np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-12)
    # The DH Panda's link frame 4 is the frame "panda_joint4": joints 5 to 7 do not move it.
    pose, J, Jp = read["panda_joint4"]
    np.testing.assert_allclose(pose, full.link_frames[3], rtol=0, atol=1e-12)
    assert np.all(J[:, 4:] == 0) and np.all(Jp[:, 4:] == 0) and np.any(J[:, :4] != 0)
    for name in ("panda_joint4", "end_effector"):
        np.testing.assert_allclose(read[name][0], full.frame_pose(name), rtol=0, atol=1e-12)
        np.testing.assert_allclose(read[name][1], full.frame_jacobian(name), rtol=0, atol=1e-12)
        np.testing.assert_allclose(read[name][2], full.frame_jacobian(name, probe.point), rtol=0, atol=1e-12)
    np.testing.assert_allclose(read["end_effector"][0], full.ee_pose, rtol=0, atol=1e-12)
    np.testing.assert_allclose(read["end_effector"][1][:3], full.J[:3], rtol=0, atol=1e-12)


def test_an_unknown_frame_or_a_wrong_point_raises_naming_it():
    robot = redres.Robot.load(source("robots/franka_panda.toml"))

    class Asks(redres.Objective):
        def __init__(self, call, **kw):
            super().__init__(**kw)
            self.call = call

        def contribute(self, ctx, qp):
            self.call(ctx)

    for call, pattern in (
            (lambda ctx: ctx.frame_pose("panda_link99"), "StepContext.frame_pose: robot 'franka_panda' has no frame "
                                                         "'panda_link99'; its frames are 'panda_joint1', .*"
                                                         "'panda_joint7', 'end_effector'"),
            (lambda ctx: ctx.frame_jacobian("elbow"),
             "StepContext.frame_jacobian: .* no frame 'elbow'; .*'end_effector'"),
            (lambda ctx: ctx.frame_jacobian("end_effector", np.zeros(2)), "point has 2 entries, expected 3"),
            (lambda ctx: ctx.frame_jacobian("end_effector", np.zeros(4)), "point has 4 entries, expected 3")):
        ctrl = redres.Controller(robot, objectives=[Asks(call, name="asks")],
                                 constraints=[redres.constraints.TaskTracking()])
        f = robot.kinematics(robot.home).f
        with pytest.raises(ValueError, match=pattern) as info:
            ctrl.step(robot.home, 0.0, f, np.zeros_like(f))
        assert any("python objective 'asks'" in n for n in info.value.__notes__)
    k = robot.kinematics(robot.home)
    with pytest.raises(ValueError, match="Kinematics.frame_pose: robot 'franka_panda' has no frame 'nope'"):
        k.frame_pose("nope")
    with pytest.raises(ValueError, match="point has 1 entries, expected 3"):
        k.frame_jacobian("end_effector", [0.0])


def test_the_frames_are_not_readable_after_the_call():
    robot = redres.Robot.load(source("robots/franka_panda.toml"))
    kept = []

    class Keeper(redres.Objective):
        def contribute(self, ctx, qp):
            kept.append(ctx)
            qp.add_identity()

    ctrl = redres.Controller(robot, objectives=[Keeper()], constraints=[redres.constraints.TaskTracking()])
    f = robot.kinematics(robot.home).f
    ctrl.step(robot.home, 0.0, f, np.zeros_like(f))
    for read in (lambda c: c.frame_pose("end_effector"), lambda c: c.frame_jacobian("end_effector"),
                 lambda c: c.frame_names, lambda c: c.link_frames):
        with pytest.raises(RuntimeError, match="outside contribute"):
            read(kept[0])


def test_a_kinematics_of_the_contexts_robot_keeps_its_frames_after_the_controller():
    """ctx.robot is borrowed from the controller; a redres.Kinematics computed from it inside the step gives the
    context's frames, and keeps its own copy of the robot, so that its frames stay readable once the controller and
    the robot are gone. (A read of a freed robot may return stale values, so the second half is a guard rather than a
    proof: only the first half is sure to fail when it is wrong.)"""
    import gc

    kept = []

    class Computes(redres.Objective):
        def contribute(self, ctx, qp):
            kept.append((ctx.robot.kinematics(ctx.theta), ctx.frame_pose("panda_joint4"),
                         ctx.frame_jacobian("end_effector", np.array([0.0, 0.0, 0.1]))))
            qp.add_identity()

    robot = redres.Robot.load(source("robots/franka_panda.toml"))
    theta = random_theta(robot, np.random.default_rng(7))
    ctrl = redres.Controller(robot, objectives=[Computes()], constraints=[redres.constraints.TaskTracking()],
                             theta0=theta)
    f = robot.kinematics(theta).f
    ctrl.step(theta, 0.0, f, np.zeros_like(f))
    del ctrl, robot
    gc.collect()
    k, pose, J = kept[0]
    assert k.frame_names[-1] == "end_effector"
    np.testing.assert_allclose(k.frame_pose("panda_joint4"), pose, rtol=0, atol=1e-12)
    np.testing.assert_allclose(k.frame_jacobian("end_effector", [0.0, 0.0, 0.1]), J, rtol=0, atol=1e-12)
    assert k.frame_names == [f"panda_joint{j}" for j in range(1, 8)] + ["end_effector"]
