"""Every public name of the redres package has a docstring: the names in redres.__all__, the typed configuration
classes of its namespaces (redres.objectives, ...), and every public method and property of each class, whether it is
defined in C++ (pybind11) or in Python. pybind11 writes a signature line into every function's __doc__, so a
function's docstring counts only with text besides its signatures (and, for an overloaded one, for every overload)."""

import inspect
import re
import types

import pytest

import redres

NAMESPACES = ("objectives", "constraints", "tasks", "paths", "engines")


def doc_text(name, obj):
    """The docstring of obj without pybind11's signature lines ('' when there is none); for an overloaded pybind11
    function, the shortest of its overloads' texts."""
    doc = inspect.getdoc(obj) or ""
    if "Overloaded function." in doc:
        blocks = re.split(rf"^\d+\. {re.escape(name)}\(.*$", doc, flags=re.M)[1:]
        return min((b.strip() for b in blocks), key=len) if blocks else ""
    lines = [line for line in doc.splitlines() if not re.match(rf"^{re.escape(name)}\(.*\)( -> .*)?$", line)]
    return "\n".join(lines).strip()


def public_members(cls):
    """(name, object) of cls's public methods and properties (its own and inherited, but not object's)."""
    for name in dir(cls):
        if name.startswith("_") or hasattr(object, name):
            continue
        attr = inspect.getattr_static(cls, name)
        if isinstance(attr, (staticmethod, classmethod)):
            yield name, attr.__func__
        elif isinstance(attr, property) or callable(attr) or type(attr).__name__ == "instancemethod":
            yield name, attr


def public_names():
    """(qualified name, name, object) of every public name the package exports."""
    out = []
    for name in redres.__all__:
        obj = getattr(redres, name)
        if isinstance(obj, types.ModuleType):
            out.append((f"redres.{name}", name, obj))
            for cls_name in sorted(n for n in vars(obj) if not n.startswith("_")):
                cls = getattr(obj, cls_name)
                out.append((f"redres.{name}.{cls_name}", cls_name, cls))
                out.extend((f"redres.{name}.{cls_name}.{m}", m, a) for m, a in public_members(cls))
        elif inspect.isclass(obj):
            out.append((f"redres.{name}", name, obj))
            out.extend((f"redres.{name}.{m}", m, a) for m, a in public_members(obj))
        else:
            out.append((f"redres.{name}", name, obj))
    return out


def test_the_walk_sees_the_whole_api():
    names = {q for q, _, _ in public_names()}
    # A sample across C++ and Python, classes, methods, properties, namespaces and their configurations.
    for expected in ("redres.Robot.kinematics", "redres.Robot.joint_names", "redres.Controller.step",
                     "redres.Controller.qp", "redres.Result.summary", "redres.Scenario.load", "redres.StepQp.add_linear",
                     "redres.Comparison.table", "redres.tasks.Frame", "redres.objectives.Manipulability.config",
                     "redres.compare", "redres.LevelInfo.priority"):
        assert expected in names, expected
    assert len(names) > 150


def test_every_public_name_has_a_docstring():
    missing = [q for q, name, obj in public_names() if not doc_text(name, obj)]
    assert not missing, "public names without a docstring:\n  " + "\n  ".join(missing)


@pytest.mark.parametrize("doc, expected", [
    ("frame_pose(self: K, name: str) -> numpy.ndarray\n", ""),
    ("frame_pose(self: K, name: str) -> numpy.ndarray\n\nworld pose\n", "world pose"),
    ("frame_pose(*args, **kwargs)\nOverloaded function.\n\n1. frame_pose(self: K) -> None\n\nfirst\n\n"
     "2. frame_pose(self: K, t: float) -> None\n", ""),
])
def test_the_signature_lines_are_not_a_docstring(doc, expected):
    def frame_pose():
        pass
    frame_pose.__doc__ = doc
    assert doc_text("frame_pose", frame_pose) == expected
