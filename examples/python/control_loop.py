"""Your own control loop around redres.Controller.step: the Panda follows a 4 cm circle with its flange while the
joint velocities stay inside their limits; the loop integrates theta itself, as a loop that drives a simulator or a
real arm would (replace the Euler line by your simulator's step, and theta by its measured joint positions).
Usage: python3 control_loop.py"""
import pathlib

import numpy as np

import redres

root = pathlib.Path(__file__).resolve().parents[2]
robot = redres.Robot.load(root / "robots" / "franka_panda.toml")
T, tau = 4.0, 0.01
controller = redres.Controller(
    robot,
    objectives=[redres.objectives.MinVelocityNorm(), redres.objectives.Manipulability(measure="log_det", p=0.5)],
    constraints=[redres.constraints.TaskTracking(gain=8.0), redres.constraints.JointAngleMargin(margin=0.05),
                 redres.constraints.JointVelocityLimits()],
    engine="newton", T=T, tau=tau)

theta = robot.home.copy()
centre = robot.kinematics(theta).f - np.array([0.04, 0.0, 0.0])
worst = 0.0
for k in range(int(round(T / tau)) + 1):
    t = k * tau
    # The desired position and velocity: a circle of radius 4 cm in the horizontal plane, once round in T.
    a, da = 2 * np.pi * t / T, 2 * np.pi / T
    r_d = centre + 0.04 * np.array([np.cos(a), np.sin(a), 0.0])
    r_d_dot = 0.04 * da * np.array([-np.sin(a), np.cos(a), 0.0])
    theta_dot, info = controller.step(theta, t, r_d, r_d_dot)
    if not info.ok:  # a failed step is a status: decide what your loop does (here: stop and say why)
        raise SystemExit(f"t = {t:.2f} s: {info.status}: {info.diagnosis}")
    worst = max(worst, np.linalg.norm(r_d - controller.f))
    theta = theta + tau * theta_dot  # your simulator's step goes here

print(f"{k + 1} steps, largest position error {worst:.2e} m, w(T) = {robot.kinematics(theta).w:.4g}")
assert worst < 1e-3
