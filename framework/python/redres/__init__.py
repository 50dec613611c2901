"""redres: redundancy resolution of redundant robot manipulators, from Python.

The library is C++; this module exposes it (not the command line):

    import redres
    robot = redres.Robot.load("robots/paper_pushrod_6dof.toml")
    k = robot.kinematics(robot.home)            # k.f, k.J, k.w, k.grad_w as numpy arrays
    s = redres.Scenario.load("configs/paper_r_tvcmm.toml", overrides={"objectives.1.p": 1.0})
    result = s.run()                            # result["manipulability"], result.summary, result.final_theta
    cmp = redres.compare(["configs/paper_r_tvcmm.toml", "configs/paper_r_mvn.toml"])

Per-step use in your own loop: redres.Controller (help(redres.Controller)). Plugins are built from their typed
configurations, e.g. redres.objectives.Manipulability(p=2.0, schedule="sine"); redres.plugins() lists every
registered plugin with its keys. Objectives and constraints can be written in Python by subclassing
redres.Objective or redres.Constraint (help(redres.Objective)); register() makes them available to scenario files.

Errors: a bad file or configuration raises redres.ConfigError (a ValueError) whose message starts with
file:line:col; a wrong size or a NaN raises ValueError naming the condition. A failed control step is not an
exception: it is a status (StepInfo.status, Result.failures and Result.first_failure).
"""

from __future__ import annotations

import atexit as _atexit
import inspect as _inspect
import json as _json
import keyword as _keyword
import math as _math
import os as _os
import sys as _sys
import tomllib as _tomllib
import types as _types
from concurrent.futures import ThreadPoolExecutor as _ThreadPoolExecutor
from typing import TYPE_CHECKING as _TYPE_CHECKING
from typing import Any as _Any
from typing import Callable as _Callable
from typing import Iterable as _Iterable
from typing import Mapping as _Mapping
from typing import Sequence as _Sequence
from typing import Union as _Union

from . import _redres
from ._redres import (  # noqa: F401  (re-exported)
    ConfigError,
    Kinematics,
    LevelInfo,
    Result,
    Robot,
    Scenario,
    StepContext,
    StepInfo,
    StepQp,
    check_plugins,
    mujoco_available,
    solve_qp,
    trajectory_column_groups,
)

if _TYPE_CHECKING:
    import numpy as _np
    from numpy.typing import ArrayLike as _ArrayLike

# The version is written once, in the top-level CMakeLists.txt's project(); the extension carries it.
__version__: str = _redres.__version__
__all__ = [
    "ConfigError", "Constraint", "Controller", "Kinematics", "LevelInfo", "Objective", "PluginConfig", "Result",
    "Robot", "Scenario", "StepContext", "StepInfo", "StepQp", "Comparison", "check_plugins", "compare", "constraints",
    "engines", "mujoco_available", "objectives", "paths", "plugins", "register", "sweep", "tasks", "velocity_limits",
    "trajectory_column_groups",
]


# --- TOML text of Python values (for overrides) -------------------------------------------------------------------

def _toml(value):
    """A Python value as TOML text, as `--set key=value` takes it."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if _math.isnan(value):
            return "nan"
        if _math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return _json.dumps(value)
    if isinstance(value, _os.PathLike):
        return _json.dumps(_os.fspath(value))
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + "}"
    if hasattr(value, "tolist"):
        return _toml(value.tolist())
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    raise TypeError(f"cannot write a value of type {type(value).__name__} as TOML")


def _load_scenario(path: _Union[str, _os.PathLike[str]],
                   overrides: _Mapping[str, _Any] | None = None) -> Scenario:
    """Loads a scenario TOML file. `overrides` maps keys to values as `redres run --set` does, e.g.
    {"objectives.1.p": 1.0, "solver.engine": "newton", "task": ["x", "y", "z", "wz"]} (array entries by 0-based
    index). A bad file or override raises redres.ConfigError with file:line:col."""
    items = None
    if overrides:
        items = [(str(k), _toml(v)) for k, v in dict(overrides).items()]
    return Scenario._load(path, items)


setattr(Scenario, "load", staticmethod(_load_scenario))  # (setattr: mypy reads the stub's Scenario.load)
Scenario.__doc__ = """A loaded scenario: a robot, theta(0), T and tau, a path, objectives, constraints and an engine.

redres.Scenario.load(path, overrides={...}) reads a scenario TOML file; scenario.run() runs it and returns a
redres.Result (the GIL is released while it runs); scenario.controller() gives a redres.Controller for its scheme."""


# --- typed plugin configurations -----------------------------------------------------------------------------------

def _camel(type_name):
    return "".join(part[:1].upper() + part[1:] for part in type_name.split("_"))


def _default_value(key):
    if key["presence"] != "optional" or key["default"] == "":
        return _inspect.Parameter.empty
    if key["default"] == "(none)":
        return None
    try:
        return _tomllib.loads("v = " + key["default"])["v"]
    except _tomllib.TOMLDecodeError:
        return key["default"]


class PluginConfig:
    """A plugin's typed configuration: its type and keys, checked when it is made (types and rules; checks that need
    the robot, such as one value per joint, run when a Controller is built). Passed to redres.Controller."""

    kind: str = ""  # "objective", "constraint", "task", "path" or "engine" (set by each configuration class)
    type: str = ""  # the plugin's type name, e.g. "min_velocity_norm"

    def __init__(self, **keys: _Any) -> None:
        """Checks `keys` against the plugin's keys (types and rules); a bad one raises redres.ConfigError naming it."""
        self._keys = dict(keys)
        _redres._check_config(self.kind, self._spec_table, self._spec_where)

    @property
    def _spec_table(self):
        table = {"engine" if self.kind == "engine" else "type": self.type}
        table.update(self._keys)
        return table

    @property
    def _spec_where(self):
        return f"redres.{self.kind}s.{type(self).__name__}"

    @property
    def config(self) -> dict[str, _Any]:
        """The keys given (the rest take their defaults)."""
        return dict(self._keys)

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self._keys.items())
        return f"redres.{self.kind}s.{type(self).__name__}({args})"


def _describe(entry):
    lines = [entry["summary"], "", "Keys:"]
    for key in entry["keys"] + entry["common_keys"]:
        presence = key["presence"] if key["presence"] != "optional" else f"default {key['default']}"
        unit = f" [{key['unit']}]" if key["unit"] else ""
        rule = f", {key['rule']}" if key["rule"] else ""
        lines.append(f"  {key['name']} ({key['type']}{unit}, {presence}{rule}): {key['help']}")
    for group, what in entry["groups"]:
        lines.append(f"  group '{group}': {what}")
    return "\n".join(lines)


def _config_class(entry):
    params = []
    seen = set()
    others = False  # keys that are not Python names (e.g. `lambda`): given as **{"lambda": ...}
    for key in entry["keys"] + entry["common_keys"]:
        if key["name"] in seen:
            continue
        seen.add(key["name"])
        if _keyword.iskeyword(key["name"]) or not key["name"].isidentifier():
            others = True
            continue
        params.append(_inspect.Parameter(key["name"], _inspect.Parameter.KEYWORD_ONLY, default=_default_value(key)))
    if others:
        params.append(_inspect.Parameter("keys", _inspect.Parameter.VAR_KEYWORD))
    cls = type(_camel(entry["type"]), (PluginConfig,), {
        "kind": entry["kind"], "type": entry["type"], "__doc__": _describe(entry),
        "__module__": f"redres.{entry['kind']}s",
    })
    setattr(cls, "__signature__", _inspect.Signature(params))
    return cls


# The namespaces of typed configurations, one per plugin kind of the library's one table of kinds
# (extend/plugin_kinds.hpp): redres.objectives, redres.constraints, redres.tasks, ...
_KINDS = {k["plural"]: k for k in _redres._plugin_kinds()}


def _namespace(plural: str) -> _types.ModuleType:
    kind = _KINDS[plural]
    module = _types.ModuleType(f"redres.{plural}", f"Typed configurations of the registered {plural.replace('_', '-')}: "
                                                   f"{kind['heading']}.")
    _sys.modules[module.__name__] = module
    return module


objectives = _namespace("objectives")
constraints = _namespace("constraints")
tasks = _namespace("tasks")
velocity_limits = _namespace("velocity_limits")
paths = _namespace("paths")
engines = _namespace("engines")
_namespaces = {_KINDS[m.__name__.split(".")[1]]["kind"]: m
               for m in (objectives, constraints, tasks, velocity_limits, paths, engines)}
if {m.__name__.split(".")[1] for m in _namespaces.values()} != set(_KINDS):
    raise ImportError("redres: the Python namespaces are not the library's plugin kinds "
                      f"({sorted(_KINDS)}): add the new kind's namespace to redres/__init__.py")


def _refresh_namespaces():
    for entry in _redres._registry():
        module = _namespaces.get(entry["kind"])
        if module is None or entry["origin"].startswith("python:"):
            continue
        name = _camel(entry["type"])
        if not hasattr(module, name):
            setattr(module, name, _config_class(entry))


def plugins(kind: str | None = None) -> list[dict[str, _Any]]:
    """Every registered plugin (objective, constraint, task, path, engine, velocity_limit) as a dict: kind, type,
    summary, origin, keys (name, default, unit, help, rule, type, presence, group), common_keys and groups. `kind`
    filters."""
    return [e for e in _redres._registry() if kind is None or e["kind"] == kind]


# --- plugins written in Python -------------------------------------------------------------------------------------

class _PythonPlugin:
    type: str | None = None  # the name under which register() files the class (default: the class name)
    keys: dict[str, _Any] = {}  # key -> default value; its type fixes how a scenario file's value is read
    help: dict[str, str] = {}   # key -> one line of help
    summary = ""         # one line, for redres.plugins() and `redres plugins`
    kinematics = "all"   # what contribute() reads: 'position', 'jacobian', 'measure' (w), 'gradient' (w, grad w), 'manipulability' (+ dJ) or 'all'
    name: str | None = None  # instance name in diagnoses (default: the type)
    active = True

    def __init__(self, **config: _Any) -> None:
        """Sets each of the class's keys (from `config`, else its default) and the common name, weight, active and
        (objectives) priority as attributes; an unknown key raises TypeError."""
        for key, default in self.keys.items():
            setattr(self, key, config.pop(key, default))
        for key in ("name", "weight", "active", "priority"):
            if key in config:
                setattr(self, key, config.pop(key))
        if config:
            raise TypeError(f"{type(self).__name__}: unknown keys {sorted(config)}; its keys are {sorted(self.keys)}")

    def contribute(self, ctx: StepContext, qp: StepQp) -> None:
        """Adds this plugin's share of the step's QP (called from the C++ step); subclasses define it."""
        raise NotImplementedError(f"{type(self).__name__}.contribute(ctx, qp)")


class Objective(_PythonPlugin):
    """Base of an objective written in Python: subclass it and define contribute(self, ctx, qp).

    contribute is called from the C++ step with the step's redres.StepContext (ctx.t, ctx.theta, ctx.J, ctx.w,
    ctx.grad_w, ctx.r_d, ..., and the robot's named frames: ctx.frame_names, ctx.frame_pose(name),
    ctx.frame_jacobian(name, point), ctx.link_frames; numpy copies, readable during the call) and the objective's
    share of the QP, a redres.StepQp: qp.add_identity(scale), qp.add_diagonal(v), qp.add_hessian(H),
    qp.add_linear(z); the objective's weight scales what it adds. Optionally define potential(self, ctx) -> float, a
    P(theta) whose gradient is the linear term per unit weight: the conformance checks (redres.check_plugins) then
    compare the two by central differences.

    Class attributes: keys (key -> default), help, summary, kinematics, type; instance attributes name, weight,
    active and priority (0, the highest, by default). Use an instance in redres.Controller(objectives=[...]), or redres.register(MyObjective) to name it
    in scenario files ([[objectives]] type = "...", its keys read as the defaults' types).

    Cost: each step calls into Python once per Python plugin (the GIL is taken, the views are made); measured
    against the same objective in C++ in docs/python.md."""

    weight = 1.0
    priority = 0         # its priority level (0 the highest; docs/tasks.md)


class Constraint(_PythonPlugin):
    """Base of a constraint written in Python: subclass it and define contribute(self, ctx, qp).

    Its rows are fixed at setup: equality_rows and inequality_rows (ints, or methods of the robot). contribute
    writes them with qp.set_equality(J, d) (J x = d) and qp.set_inequality(A, b) (A x <= b), and may narrow the
    bounds with qp.intersect_bounds(lower, upper) or qp.intersect_bound(joint, lower, upper). Optionally:
    describe_inequality_row(i) for diagnoses, violated() and describe_violation() to fail a step. Constraints
    are hard and have no weight. See redres.Objective for ctx, keys, register() and the cost."""

    equality_rows = 0
    inequality_rows = 0


def register(cls: type[Objective] | type[Constraint], type: str | None = None, replace: bool = False) -> str:
    """Makes a redres.Objective or redres.Constraint subclass available to scenario files and the registries under
    `type` (default: cls.type or the class name). Its keys are read from the TOML table with the types of its
    defaults; instances are made as cls(**keys). replace=True first drops a class registered before from the same
    module and name (e.g. when a notebook cell runs again). Returns the origin, 'python:<module>.<qualname>', for
    check_plugins(origin)."""
    if issubclass(cls, Constraint):
        kind = "constraint"
    elif issubclass(cls, Objective):
        kind = "objective"
    else:
        raise TypeError("register: expected a subclass of redres.Objective or redres.Constraint")
    name = type or cls.type or cls.__name__
    if replace:
        _redres._unregister(f"python:{cls.__module__}.{cls.__qualname__}")
    return _redres._register_class(kind, name, cls, dict(cls.keys), dict(cls.help), cls.summary or cls.__doc__ or "")


_atexit.register(_redres._unregister_all)


# --- controllers ---------------------------------------------------------------------------------------------------

class Controller(_redres.Controller):
    """The per-step API for your own control loop (e.g. one that drives a physics simulator).

        ctrl = redres.Controller(robot,
                                 objectives=[redres.objectives.MinVelocityNorm(),
                                             redres.objectives.Manipulability(p=2.0, schedule="sine")],
                                 constraints=[redres.constraints.TaskTracking(gain=8.0),
                                              redres.constraints.JointVelocityLimits()],
                                 engine="newton",                  # or redres.engines.Newton(tolerance=1e-8)
                                 path=redres.paths.Circle(radius=0.05),   # optional
                                 T=10.0, tau=0.01, theta0=theta)
        theta_dot, info = ctrl.step(theta, t)                 # r_d, r_d_dot from the path
        theta_dot, info = ctrl.step(theta, t, r_d, r_d_dot)   # or your own (reference_dim entries)

    Objectives and constraints are typed configurations (redres.objectives.*, redres.constraints.*) or instances of
    Python subclasses of redres.Objective / redres.Constraint; tasks are typed configurations (redres.tasks.*, as
    [[tasks]] in a scenario), each at a priority: with several priorities the step solves the levels in turn
    (docs/tasks.md) and info.levels reports each. The path is placed at the end effector's position at theta0
    (default: the robot's home). info is a redres.StepInfo: a step that does not solve has info.ok False and a
    diagnosis; it does not raise. Controller.from_scenario(s) steps a loaded scenario's scheme. ctrl.qp is the last
    step's QP; ctrl.f, ctrl.r_d and ctrl.w its task values. The GIL is released during a step (taken again only for
    Python plugins)."""

    def __init__(self, robot: Robot, objectives: _Iterable[_Any] = (), constraints: _Iterable[_Any] = (),
                 tasks: _Iterable[PluginConfig] = (), engine: _Union[str, PluginConfig] = "newton",
                 path: PluginConfig | None = None, T: float = 1.0, tau: float = 0.01,
                 theta0: _ArrayLike | None = None, level: str = "velocity", regularization: float | None = None,
                 orientation_turn: _Union[float, _ArrayLike, None] = None) -> None:
        """Builds the scheme for `robot` (a redres.Robot) from `objectives`, `constraints` (typed configurations or
        Python plugin instances) and `tasks` (redres.tasks.* configurations), at `level` ('velocity' or
        'acceleration'); the LVI engine (a name or a redres.engines.* configuration), and the optional path (a
        redres.paths.* configuration, placed at f(theta0)). T is the task duration and tau the control step (s), both
        visible to the plugins. regularization is the eps |x|^2 / 2 of every priority level (a scenario's [scheme]
        regularization; default 1e-9); orientation_turn the rotation the end effector turns through over T (a
        scenario's [orientation] turn: rad, a number for a planar robot, a rotation vector (3,) for a spatial one).
        Everything is sized here: step() allocates nothing.

        Unlike a scenario file, nothing is added for you: list JointAccelerationLimits() and JointJerkLimits() among
        the constraints to hold a robot file's acceleration and jerk limits (a scenario adds them when it lists
        none)."""
        super().__init__(robot, list(objectives), list(constraints), engine=engine, path=path, T=T, tau=tau,
                         theta0=theta0, level=level, tasks=list(tasks), regularization=regularization,
                         orientation_turn=orientation_turn)

    @staticmethod
    def from_scenario(scenario: Scenario) -> _redres.Controller:
        """The controller that `redres run` simulates for a loaded redres.Scenario: its scheme, engine and path, its
        orientation turn, and its [solver] on_infeasible policy (with "relax", the elastic QP). Same as
        scenario.controller()."""
        return scenario.controller()


# --- comparisons ---------------------------------------------------------------------------------------------------

class Comparison:
    """Several runs side by side: results (redres.Result, in the given order), table() (one dict per run, keyed as
    the columns of `redres compare`'s comparison.csv, with numbers as numbers) and markdown() (comparison.md's
    table, with its headings). The columns come from the one list the CLI uses."""

    columns = tuple(key for key, _ in _redres._comparison([])[0])  # comparison.csv's heading, in order
    headings = tuple(heading for _, heading in _redres._comparison([])[0])  # comparison.md's

    def __init__(self, results: _Iterable[Result]) -> None:
        """Holds `results` (redres.Result objects) in the given order."""
        self.results: list[Result] = list(results)

    def __getitem__(self, name: str) -> Result:
        """The run named `name` (its scenario's name); KeyError when there is none."""
        for r in self.results:
            if r.name == name:
                return r
        raise KeyError(name)

    def table(self) -> list[dict[str, _Any]]:
        """One dict per run, keyed as comparison.csv's columns (Comparison.columns), numbers as numbers."""
        columns, rows, _ = _redres._comparison(self.results)
        keys = [key for key, _ in columns]
        return [dict(zip(keys, row)) for row in rows]

    def markdown(self) -> str:
        """comparison.md's table, with its headings (Comparison.headings), as `redres compare` writes it."""
        return _redres._comparison(self.results)[2]

    def __repr__(self) -> str:
        return f"<redres.Comparison of {len(self.results)} runs>"


def compare(scenarios: _Iterable[_Union[str, _os.PathLike[str], Scenario]],
            overrides: _Mapping[str, _Any] | None = None, jobs: int | None = None) -> Comparison:
    """Runs several scenarios (paths or loaded redres.Scenario objects; `overrides` apply to those given as paths)
    on `jobs` threads (default: one per core, at most one per scenario) and returns a redres.Comparison. Every file
    is loaded before any run starts, so a bad one raises before anything runs."""
    loaded = [s if isinstance(s, Scenario) else Scenario.load(s, overrides) for s in scenarios]
    if jobs is None:
        jobs = max(1, min(len(loaded), _os.cpu_count() or 1))
    with _ThreadPoolExecutor(max_workers=jobs) as pool:
        results = list(pool.map(lambda s: s.run(), loaded))
    return Comparison(results)


def sweep(path: _Union[str, _os.PathLike[str]], jobs: int | None = None, shard: str | None = None,
          out_dir: _Union[str, _os.PathLike[str], None] = None) -> list[dict[str, _Any]]:
    """Runs a sweep file (docs/sweeps.md) as `redres sweep` does, on `jobs` threads (default: one per core) with the
    GIL released, and returns its table: a list of dicts, one per variation in variation order, with the axes'
    values, status, diagnosis and every summary figure, as Python values: numbers as int or float, flags as bool,
    text as str, and None for a figure a failed run has not (sweep.csv holds the same as text). shard="i/N" runs one slice;
    out_dir receives runs/<index>/ when the sweep file asks for each run's directory."""
    columns, rows = _redres._sweep(path, jobs or 0, shard or "", _os.fspath(out_dir) if out_dir else "")
    return [dict(zip(columns, row)) for row in rows]


def _result_summary(self: Result) -> dict[str, _Any]:
    """summary.json of the run, as a dict (docs/output_formats.md)."""
    return _json.loads(self.summary_json)


def _result_trajectory(self: Result) -> dict[str, _np.ndarray]:
    """Every column as a dict of numpy arrays (views of the run's row-major table, no copy)."""
    return {name: self[name] for name in self.columns}


setattr(Result, "summary", property(_result_summary))  # (setattr: mypy reads the stub's properties)
setattr(Result, "trajectory", property(_result_trajectory))

_refresh_namespaces()
