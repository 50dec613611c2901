"""An objective written in Python and used from a scenario file: a joint-centering variant that pulls each joint
towards the middle of its range, weighted by how close the joint is to a limit (a quartic potential). It is
registered under `centering_quartic`, and centering_scenario.toml names it in [[objectives]] like a built-in.
Usage: python3 python_objective.py"""
import pathlib

import numpy as np

import redres


class QuarticCentering(redres.Objective):
    """Pulls joints towards mid-range: P(theta) = gain * sum(((theta - mid) / half_range)^4) / 4."""

    type = "centering_quartic"
    keys = {"gain": 0.1}
    help = {"gain": "strength of the pull (rad/s per unit of normalised offset cubed)"}
    kinematics = "position"  # it reads theta only

    def contribute(self, ctx, qp):
        robot = ctx.robot
        mid = 0.5 * (robot.lower_limits + robot.upper_limits)
        half = 0.5 * (robot.upper_limits - robot.lower_limits)
        u = (ctx.theta - mid) / half
        qp.add_linear(self.gain * u**3 / half)  # the gradient of the potential below

    def potential(self, ctx):
        robot = ctx.robot
        mid = 0.5 * (robot.lower_limits + robot.upper_limits)
        half = 0.5 * (robot.upper_limits - robot.lower_limits)
        return float(self.gain * np.sum(((ctx.theta - mid) / half) ** 4) / 4)


origin = redres.register(QuarticCentering)
failed = [c for c in redres.check_plugins(origin) if not c["ok"]]  # the checks the C++ plugins pass
assert not failed, failed

here = pathlib.Path(__file__).resolve().parent
with_it = redres.Scenario.load(here / "centering_scenario.toml").run()
without = redres.Scenario.load(here / "centering_scenario.toml", overrides={"objectives.1.active": False}).run()
for name, result in (("with centering_quartic", with_it), ("without", without)):
    theta = result.final_theta
    print(f"{name:24s} final theta {np.array2string(theta, precision=3)}  max position error "
          f"{result.summary['max_position_error']:.2e} m")
def spread(result):
    """sum(u^4) / 4 at T, u the joints' offsets from mid-range as fractions of half their range: what the
    objective lowers (its potential per unit gain)."""
    lower = np.array(result.summary["robot"]["lower_limits"])
    upper = np.array(result.summary["robot"]["upper_limits"])
    u = (result.final_theta - (lower + upper) / 2) / ((upper - lower) / 2)
    return float(np.sum(u**4) / 4)


assert with_it.failures == 0 and without.failures == 0
print(f"sum(u^4)/4 at T: {spread(with_it):.4f} with centering_quartic, {spread(without):.4f} without")
assert spread(with_it) < spread(without)
