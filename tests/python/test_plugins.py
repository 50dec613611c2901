"""Plugins from Python: typed configurations of every registered plugin, the registry's listing, and objectives and
constraints written in Python, called from the C++ step: a Python min_velocity_norm gives the C++ run bit for bit,
the conformance checks run on them (and catch a wrong gradient), and their errors name them."""

import json

import numpy as np
import pytest

import redres
from conftest import cli, source


def test_every_registered_plugin_has_a_typed_configuration():
    listed = json.loads(cli("plugins", "--json").stdout)
    for kind, module in (("objectives", redres.objectives), ("constraints", redres.constraints),
                         ("tasks", redres.tasks), ("paths", redres.paths), ("engines", redres.engines)):
        types = [e["type"] for e in listed[kind]]
        assert types, kind
        for t in types:
            cls = getattr(module, "".join(p.capitalize() for p in t.split("_")))
            assert cls.type == t
    m = redres.objectives.Manipulability(p=2.0, schedule="sine")
    assert m.config == {"p": 2.0, "schedule": "sine"}
    assert "p" in str(__import__("inspect").signature(redres.objectives.Manipulability))
    assert "schedule" in redres.objectives.Manipulability.__doc__
    kinds = {e["kind"] for e in redres.plugins()}
    assert kinds == {"objective", "constraint", "task", "path", "engine", "velocity_limit"}
    # One namespace per kind of the library's table of kinds, and the same plugins as `redres plugins --json` lists.
    for kind in kinds:
        plural = kind + "s"
        assert isinstance(getattr(redres, plural), type(redres)), plural
        assert plural in redres.__all__
        built_in = {e["type"] for e in redres.plugins(kind) if e["origin"] == "built-in"}
        assert {e["type"] for e in listed[plural] if e["origin"] == "built-in"} == built_in


def test_bad_typed_configurations_raise_naming_the_key():
    with pytest.raises(redres.ConfigError, match="key 'q': unknown key"):
        redres.objectives.Manipulability(q=1.0)
    with pytest.raises(redres.ConfigError, match="key 'schedule'"):
        redres.objectives.Manipulability(schedule="weekly")
    with pytest.raises(redres.ConfigError, match="key 'gain'"):
        redres.constraints.TaskTracking(gain=-1.0)
    with pytest.raises(redres.ConfigError, match="weight"):
        redres.constraints.TaskTracking(weight=2.0)
    with pytest.raises(TypeError, match="key 'p'"):
        redres.objectives.Manipulability(p=object())


class PyMinVelocityNorm(redres.Objective):
    """x'x/2, as min_velocity_norm, written in Python."""
    type = "py_min_velocity_norm"
    kinematics = "position"

    def contribute(self, ctx, qp):
        qp.add_identity(1.0)


class PyCentering(redres.Objective):
    """Pulls each joint towards the middle of its range: zeta = gain (theta - mid) / range^2."""
    type = "py_centering"
    keys = {"gain": 1.0}
    help = {"gain": "strength (1/s)"}

    def _terms(self, ctx):
        robot = ctx.robot
        mid = (robot.lower_limits + robot.upper_limits) / 2
        span = robot.upper_limits - robot.lower_limits
        return mid, span

    def contribute(self, ctx, qp):
        mid, span = self._terms(ctx)
        qp.add_linear(self.gain * (ctx.theta - mid) / span**2)

    def potential(self, ctx):
        mid, span = self._terms(ctx)
        return float(0.5 * self.gain * np.sum((ctx.theta - mid) ** 2 / span**2))


class WrongGradient(PyCentering):
    type = "py_wrong_gradient"

    def potential(self, ctx):
        return 2.0 * super().potential(ctx)


class SpeedCap(redres.Constraint):
    """|theta_dot_i| <= cap, as bounds; and sum(theta_dot) <= total as one inequality row."""
    type = "py_speed_cap"
    keys = {"cap": 0.5, "total": 10.0}
    inequality_rows = 1
    kinematics = "position"

    def contribute(self, ctx, qp):
        n = qp.n
        qp.intersect_bounds(np.full(n, -self.cap), np.full(n, self.cap))
        qp.set_inequality(np.ones((1, n)), np.array([self.total]))

    def describe_inequality_row(self, i):
        return "sum of the joint speeds"


@pytest.fixture(scope="module", autouse=True)
def registered():
    return [redres.register(cls, replace=True) for cls in (PyMinVelocityNorm, PyCentering, WrongGradient, SpeedCap)]


def test_a_python_min_velocity_norm_gives_the_cpp_run_bit_for_bit():
    cpp = redres.Scenario.load(source("configs/paper_r_mvn.toml")).run()
    py = redres.Scenario.load(source("configs/paper_r_mvn.toml"),
                              overrides={"objectives.0.type": "py_min_velocity_norm"}).run()
    assert py.failures == 0
    assert py.final_theta.tolist() == cpp.final_theta.tolist()
    assert np.array_equal(py["manipulability"], cpp["manipulability"])
    # The same from instances given to a Controller.
    robot = redres.Robot.load(source("robots/paper_pushrod_6dof.toml"))
    for objective in (PyMinVelocityNorm(), redres.objectives.MinVelocityNorm()):
        ctrl = redres.Controller(robot, objectives=[objective], constraints=[redres.constraints.TaskTracking()],
                                 T=1.0, tau=0.01)
        f = robot.kinematics(robot.home).f
        assert ctrl.qp["W"].shape == (6, 6)
        x, info = ctrl.step(robot.home, 0.0, f, np.array([0.01, 0.0]))
        assert info.ok
        if isinstance(objective, PyMinVelocityNorm):
            first = x
    assert np.array_equal(first, x)


def test_python_plugins_pass_the_conformance_checks_and_a_wrong_gradient_fails(registered):
    for origin in registered:
        results = redres.check_plugins(origin)
        assert results, origin
        failed = [r for r in results if not r["ok"]]
        if origin.endswith("WrongGradient"):
            assert [r["check"] for r in failed] == ["gradient"] * len(failed) and failed
        else:
            assert not failed, failed
    gradient = [r for r in redres.check_plugins(registered[1]) if r["check"] == "gradient"]
    assert len(gradient) == 3, "checked on each of the three test robots"


def test_registered_python_plugins_are_listed_with_their_keys():
    entry = next(e for e in redres.plugins("objective") if e["type"] == "py_centering")
    assert entry["origin"] == "python:test_plugins.PyCentering"
    assert entry["keys"][0]["name"] == "gain" and entry["keys"][0]["default"] == "1.0"
    assert entry["keys"][0]["help"] == "strength (1/s)"


def test_a_python_constraint_holds_in_a_scenario():
    s = redres.Scenario.load(source("configs/panda_helix.toml"), overrides={
        "constraints.2.type": "py_speed_cap", "constraints.2.cap": 0.3})
    r = s.run()
    speeds = np.column_stack([r[f"theta_dot_{j}"] for j in range(1, 8)])
    assert np.abs(speeds).max() <= 0.3 + 1e-12
    assert r.summary["max_position_error"] < 1e-3


def test_a_python_objective_used_from_a_scenario_file_key_reads_its_keys():
    s = redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={
        "objectives.1": {"type": "py_centering", "gain": 0.5}})
    r = s.run()
    assert r.failures == 0
    with pytest.raises(redres.ConfigError, match="'gain'"):
        redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={
            "objectives.1": {"type": "py_centering", "gain": "strong"}})
    with pytest.raises(redres.ConfigError, match="unknown key"):
        redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={
            "objectives.1": {"type": "py_centering", "strength": 1.0}})


def test_errors_inside_python_plugins_name_the_plugin():
    class Broken(redres.Objective):
        def contribute(self, ctx, qp):
            raise ZeroDivisionError("boom")

    class WrongShape(redres.Objective):
        def contribute(self, ctx, qp):
            qp.add_linear(np.zeros(3))

    robot = redres.Robot.load(source("robots/paper_pushrod_6dof.toml"))
    # The exception keeps its type; a note names the plugin.
    for plugin, kind, pattern, note in (
            (Broken(name="broken"), ZeroDivisionError, "boom", "python objective 'broken'"),
            (WrongShape(), ValueError, "the linear term is 3 x 1, expected 6 x 1", "python objective 'WrongShape'")):
        ctrl = redres.Controller(robot, objectives=[plugin], constraints=[redres.constraints.TaskTracking()])
        with pytest.raises(kind, match=pattern) as info:
            ctrl.step(robot.home, 0.0, robot.kinematics(robot.home).f, np.zeros(2))
        assert any(note in n for n in info.value.__notes__), info.value.__notes__


def test_the_context_is_not_usable_after_the_call():
    kept = []

    class Keeper(redres.Objective):
        def contribute(self, ctx, qp):
            kept.append((ctx, ctx.J.copy(), ctx.w))
            qp.add_identity()

    robot = redres.Robot.load(source("robots/paper_pushrod_6dof.toml"))
    ctrl = redres.Controller(robot, objectives=[Keeper()], constraints=[redres.constraints.TaskTracking()])
    ctrl.step(robot.home, 0.0, robot.kinematics(robot.home).f, np.zeros(2))
    ctx, J, w = kept[0]
    k = robot.kinematics(robot.home)
    assert np.array_equal(J, k.J) and w == k.w
    with pytest.raises(RuntimeError, match="outside contribute"):
        ctx.theta
