"""The Python API is memory-safe and honest about threads (the second reliability probe): arrays a plugin keeps from
its step context are copies that outlive the step and the controller; one controller stepped from two threads gives
each step the answer of a controller stepped alone; a plugin that steps its own controller or runs its own scenario
is refused at once (it used to return the inner step's answer, or wait for ever); a plugin's exception reaches the
caller as itself (a KeyboardInterrupt stays one) with a note naming the plugin; and NaN input raises."""

import gc
import signal
import threading

import numpy as np
import pytest

import redres
from conftest import source

ROBOT = "robots/paper_pushrod_6dof.toml"


def controller(robot, objective, engine="newton"):
    return redres.Controller(robot, objectives=[objective, redres.objectives.MinVelocityNorm()],
                             constraints=[redres.constraints.TaskTracking()], engine=engine)


class Keeper(redres.Objective):
    """Keeps what it reads, without copying."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.kept = []

    def contribute(self, ctx, qp):
        self.kept.append((ctx.theta, ctx.J, ctx.grad_w, ctx.r_d))
        qp.add_identity(0.0)


def test_arrays_kept_from_the_context_outlive_the_step_and_the_controller():
    robot = redres.Robot.load(source(ROBOT))
    keeper = Keeper()
    ctrl = controller(robot, keeper)
    thetas = [robot.home, robot.home + 0.05, robot.home - 0.05]
    for theta in thetas:
        k = robot.kinematics(theta)
        ctrl.step(theta, 0.0, k.f, np.zeros(2))
    del ctrl
    gc.collect()
    big = [np.full((6, 6), 7.0) for _ in range(100)]  # reuse the freed memory
    for (theta, J, grad_w, r_d), want in zip(keeper.kept, thetas):
        k = robot.kinematics(want)
        assert np.array_equal(theta, want)
        assert np.array_equal(J, k.J)
        assert np.array_equal(grad_w, k.grad_w)
        assert np.array_equal(r_d, k.f)
    assert big[0][0, 0] == 7.0


def test_two_threads_stepping_one_controller_get_the_answers_of_one_thread():
    robot = redres.Robot.load(source(ROBOT))
    rng = np.random.default_rng(5)
    lo, hi = robot.lower_limits, robot.upper_limits
    states = [lo + (hi - lo) * (0.3 + 0.4 * rng.random(6)) for _ in range(300)]
    alone = controller(robot, redres.objectives.Manipulability(p=1.0))
    want = []
    for theta in states:
        alone.reset()
        x, info = alone.step(theta, 0.0, robot.kinematics(theta).f, np.array([0.01, -0.01]))
        want.append((x, info.ok))
    shared = controller(robot, redres.objectives.Manipulability(p=1.0))
    got = [None] * len(states)
    errors = []

    def work(part):
        try:
            for i in range(part, len(states), 2):
                theta = states[i]
                x, info = shared.step(theta, 0.0, robot.kinematics(theta).f, np.array([0.01, -0.01]))
                got[i] = (x, info.ok)
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=work, args=(p,)) for p in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    worst = max(np.abs(g[0] - w[0]).max() for g, w in zip(got, want))
    assert all(g[1] == w[1] for g, w in zip(got, want))
    assert worst < 1e-6, f"theta_dot differs by {worst} from a controller stepped alone (warm starts differ only)"


class Reentrant(redres.Objective):
    """Steps the controller it is part of, from inside that controller's step."""
    target = None

    def contribute(self, ctx, qp):
        if Reentrant.target is not None:
            Reentrant.target.step(ctx.theta, ctx.t, ctx.r_d, ctx.r_d_dot)
        qp.add_identity(0.0)


def test_a_plugin_that_steps_its_own_controller_is_refused():
    robot = redres.Robot.load(source(ROBOT))
    ctrl = controller(robot, Reentrant())
    Reentrant.target = ctrl
    with pytest.raises(RuntimeError, match=r"Controller.step: called again from inside its own step"):
        ctrl.step(robot.home, 0.0, robot.kinematics(robot.home).f, np.zeros(2))
    Reentrant.target = None
    # The controller is free again afterwards.
    x, info = ctrl.step(robot.home, 0.0, robot.kinematics(robot.home).f, np.zeros(2))
    assert info.ok


def test_a_controller_whose_init_raised_raises_instead_of_crashing():
    robot = redres.Robot.load(source(ROBOT))
    half = redres.Controller.__new__(redres.Controller)  # what a traceback keeps when __init__ raises
    assert repr(half) == "<redres.Controller, never made>"
    with pytest.raises(RuntimeError, match="this controller was never made"):
        half.step(robot.home, 0.0)
    with pytest.raises(RuntimeError, match="this controller was never made"):
        half.w


class RunsItsScenario(redres.Objective):
    """Runs the scenario it is part of, from inside its step (waited for ever before)."""
    type = "py_runs_its_scenario"
    scenario = []

    def contribute(self, ctx, qp):
        if RunsItsScenario.scenario:
            RunsItsScenario.scenario[0].run()
        qp.add_identity(0.0)


class Raises(redres.Objective):
    type = "py_raises"
    keys = {"what": "custom"}

    def contribute(self, ctx, qp):
        if self.what == "interrupt":
            signal.raise_signal(signal.SIGINT)  # Ctrl-C, as the terminal sends it
            for _ in range(1000):  # the handler runs between bytecodes
                pass
        raise CustomError("from the plugin")


class CustomError(Exception):
    pass


@pytest.fixture(scope="module", autouse=True)
def registered():
    return [redres.register(cls, replace=True) for cls in (RunsItsScenario, Raises)]


def test_a_plugin_that_runs_its_own_scenario_is_refused_not_deadlocked():
    s = redres.Scenario.load(source("configs/paper_r_fast.toml"), overrides={
        "objectives.1": {"type": "py_runs_its_scenario"}})
    RunsItsScenario.scenario.append(s)
    try:
        with pytest.raises(RuntimeError, match="Scenario.run: called again from inside its own step"):
            s.run()
    finally:
        RunsItsScenario.scenario.clear()
    assert s.run().failures == 0  # free again


def test_a_plugins_exception_keeps_its_type_and_names_the_plugin():
    robot = redres.Robot.load(source(ROBOT))
    ctrl = controller(robot, Raises(name="thrower"))
    with pytest.raises(CustomError, match="from the plugin") as info:
        ctrl.step(robot.home, 0.0, robot.kinematics(robot.home).f, np.zeros(2))
    assert any("python objective 'thrower'" in n for n in getattr(info.value, "__notes__", [])), info.value
    s = redres.Scenario.load(source("configs/paper_r_fast.toml"), overrides={"objectives.1": {"type": "py_raises"}})
    with pytest.raises(CustomError):
        s.run()


def test_ctrl_c_inside_a_plugin_is_a_keyboard_interrupt():
    robot = redres.Robot.load(source(ROBOT))
    ctrl = controller(robot, Raises(what="interrupt"))
    with pytest.raises(KeyboardInterrupt):
        ctrl.step(robot.home, 0.0, robot.kinematics(robot.home).f, np.zeros(2))
    s = redres.Scenario.load(source("configs/paper_r_fast.toml"), overrides={
        "objectives.1": {"type": "py_raises", "what": "interrupt"}})
    with pytest.raises(KeyboardInterrupt):
        s.run()


def test_nan_and_wrong_sizes_raise_naming_the_condition():
    robot = redres.Robot.load(source(ROBOT))
    theta = robot.home.copy()
    theta[2] = np.nan
    with pytest.raises(ValueError, match=r"Robot.velocity_limits: theta is finite \(theta\[2\] = nan\)"):
        robot.velocity_limits(theta)
    with pytest.raises(ValueError, match=r"Robot.kinematics: theta is finite"):
        robot.kinematics(theta)
    with pytest.raises(ValueError, match="theta has 5 entries, expected dof = 6"):
        robot.velocity_limits(robot.home[:5])


def test_a_library_whose_initialisers_throw_leaves_loading_and_registering_working(tmp_path):
    import os
    import pathlib
    library = pathlib.Path(os.environ["REDRES_CLI"]).resolve().parents[1] / "test-plugins-hostile" / \
        "libredres_test_plugin_throw.so"
    assert library.is_file(), library
    text = pathlib.Path(source("configs/paper_r_fast.toml")).read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(f'plugins = ["{library}"]\n' + text.replace('"../robots/', f'"{source("robots")}/'))
    with pytest.raises(redres.ConfigError, match="its static initialisers threw std::runtime_error"):
        redres.Scenario.load(str(bad))
    assert not any(e["type"] == "test_registered_before_the_failure" for e in redres.plugins("objective"))
    # Loading from another thread, and registering, go on as before.
    out = {}
    worker = threading.Thread(target=lambda: out.setdefault("r", redres.Scenario.load(
        source("configs/paper_r_fast.toml")).run()))
    worker.start()
    worker.join(timeout=60)
    assert not worker.is_alive() and out["r"].failures == 0

    class Later(redres.Objective):
        type = "py_registered_after_a_bad_library"

        def contribute(self, ctx, qp):
            qp.add_identity(0.0)
    redres.register(Later, replace=True)
    assert any(e["type"] == "py_registered_after_a_bad_library" for e in redres.plugins("objective"))
