"""A small program that uses the redres API, for mypy (check_typing.py): it must type-check as it is."""

import numpy as np
import numpy.typing as npt

import redres


class Centering(redres.Objective):
    """Pulls the joints towards mid-range."""

    type = "py_centering_typed"
    keys = {"gain": 1.0}
    help = {"gain": "strength (1/s)"}
    kinematics = "position"
    gain = 1.0

    def contribute(self, ctx: redres.StepContext, qp: redres.StepQp) -> None:
        mid = (ctx.robot.lower_limits + ctx.robot.upper_limits) / 2
        qp.add_linear(self.gain * (ctx.theta - mid))


def tool_height(robot: redres.Robot, theta: npt.NDArray[np.float64]) -> float:
    k: redres.Kinematics = robot.kinematics(theta)
    pose = k.frame_pose("end_effector")
    return float(pose[2, 3]) + k.w * 0.0


def main(root: str) -> None:
    robot = redres.Robot.load(f"{root}/robots/franka_panda.toml")
    names: list[str] = robot.joint_names
    height = tool_height(robot, robot.home)
    lo, hi = robot.velocity_limits(robot.home)
    ctrl = redres.Controller(
        robot,
        objectives=[redres.objectives.MinVelocityNorm(weight=0.01, priority=1), Centering(gain=0.5)],
        constraints=[redres.constraints.JointVelocityLimits()],
        tasks=[redres.tasks.Frame(frame="end_effector", reference="path")],
        path=redres.paths.Circle(radius=0.05),
        T=2.0,
        tau=0.01,
        regularization=1e-9,
    )
    theta = robot.home.copy()
    theta_dot, info = ctrl.step(theta, 0.0)
    ok: bool = info.ok
    levels: list[int] = [level.priority for level in info.levels]
    qp: dict[str, npt.NDArray[np.float64]] = ctrl.qp
    s = redres.Scenario.load(f"{root}/configs/paper_r_fast.toml", overrides={"solver.engine": "newton"})
    result = s.run(progress=lambda fraction, t: None)
    column: npt.NDArray[np.float64] = result["manipulability"]
    summary = result.summary
    comparison = redres.compare([s], jobs=1)
    rows = comparison.table()
    version: str = redres.__version__
    print(names, height, lo, hi, theta_dot, ok, levels, qp["W"], column, summary, rows, version)
