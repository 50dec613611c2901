"""Sweeps from Python and the heat map: redres.sweep gives the rows of `redres sweep`'s sweep.csv, and
tools/plot_sweep.py draws the shipped kind of figure from a sweep directory."""

import csv
import os
import subprocess
import sys

import redres
from conftest import cli, source


def test_a_python_sweep_gives_the_rows_of_the_cli(tmp_path):
    p = cli("sweep", source("tests/data/sweeps/small.toml"), "--quiet", "--out", str(tmp_path))
    assert p.returncode == 1, p.stderr  # some variations fail on purpose
    with open(tmp_path / "sweep.csv", newline="") as f:
        want = list(csv.DictReader(f))
    got = redres.sweep(source("tests/data/sweeps/small.toml"), jobs=2)
    assert got == want
    assert [r["status"] for r in got].count("ok") == 4


def test_the_heat_map_marks_the_variations_that_did_not_run_through(tmp_path):
    cli("sweep", source("tests/data/sweeps/small.toml"), "--quiet", "--out", str(tmp_path))
    tool = source("tools/plot_sweep.py")
    p = subprocess.run([sys.executable, tool, str(tmp_path)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert os.path.getsize(tmp_path / "sweep_heatmap.png") > 5000
    bad = subprocess.run([sys.executable, tool, str(tmp_path), "--x", "nope"], capture_output=True, text=True)
    assert bad.returncode == 2 and "'nope' is not a column" in bad.stderr
