"""Shared fixtures of the Python tests. ctest runs them with the build's package on PYTHONPATH and REDRES_CLI naming
the build's `redres` executable (tests/CMakeLists.txt)."""

import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAPER_THETA0 = np.array([np.pi / 4, np.pi / 12, np.pi / 12, np.pi / 12, np.pi / 36, np.pi / 36])


def source(relative):
    return str(ROOT / relative)


def cli(*args, cwd=None):
    """Runs the build's redres CLI; returns the completed process (stdout and stderr as text)."""
    exe = os.environ.get("REDRES_CLI")
    if not exe:
        pytest.fail("REDRES_CLI is not set: run the Python tests through ctest")
    return subprocess.run([exe, *args], capture_output=True, text=True, cwd=cwd, check=False)


def cli_run(config, out, *sets):
    """`redres run CONFIG --out OUT --quiet [--set ...]` and its summary.json."""
    args = ["run", source(config), "--out", str(out), "--quiet"]
    for s in sets:
        args += ["--set", s]
    p = cli(*args)
    assert p.returncode == 0, p.stderr
    return json.loads((pathlib.Path(out) / "summary.json").read_text())
