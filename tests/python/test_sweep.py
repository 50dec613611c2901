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
    assert [list(r) for r in got] == [list(r) for r in want]  # the same columns in the same order
    # The same cells, as Python values: numbers as numbers (equal to the CSV's text), flags as bool, text as str.
    for g, w in zip(got, want):
        for key, value in g.items():
            text = w[key]
            if value is None:
                assert text == "", (key, text)
            elif isinstance(value, bool):
                assert text == ("true" if value else "false"), (key, text)
            elif isinstance(value, (int, float)):
                assert value == float(text), (key, value, text)
            else:
                assert isinstance(value, str) and value == text, (key, value, text)
    first = next(r for r in got if r["status"] == "ok")
    assert isinstance(first["index"], int)
    assert isinstance(first["max_position_error"], float) and isinstance(first["solver.failures"], int)
    assert isinstance(first["solver.stopped"], bool) and isinstance(first["status"], str)
    assert [r["status"] for r in got].count("ok") == 4


def test_the_heat_map_marks_the_variations_that_did_not_run_through(tmp_path):
    cli("sweep", source("tests/data/sweeps/small.toml"), "--quiet", "--out", str(tmp_path))
    tool = source("tools/plot_sweep.py")
    p = subprocess.run([sys.executable, tool, str(tmp_path)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert os.path.getsize(tmp_path / "sweep_heatmap.png") > 5000
    bad = subprocess.run([sys.executable, tool, str(tmp_path), "--x", "nope"], capture_output=True, text=True)
    assert bad.returncode == 2 and "'nope' is not a column" in bad.stderr


def test_a_sweep_that_writes_its_runs_without_out_dir_gets_a_private_directory_it_names(tmp_path):
    import shutil
    import stat
    import warnings

    sweep_file = tmp_path / "runs.toml"
    sweep_file.write_text(f'name = "runs"\nscenario = "{source("configs/paper_r_fast.toml")}"\n'
                          '[[vary]]\nkey = "objectives.1.p"\nvalues = [1.0, 2.0]\n[output]\nruns = true\n')
    dirs = []
    for _ in range(2):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            rows = redres.sweep(str(sweep_file), jobs=1)
        assert [r["status"] for r in rows] == ["ok", "ok"]
        said = [str(w.message) for w in caught if "no out_dir" in str(w.message)]
        assert len(said) == 1, [str(w.message) for w in caught]
        where = said[0].split("written into ")[1]
        dirs.append(where)
        assert stat.S_IMODE(os.lstat(where).st_mode) == 0o700
        assert os.path.isfile(os.path.join(where, "runs", "1", "summary.json"))
    assert dirs[0] != dirs[1]  # a new directory each time, never a fixed name
    for d in dirs:
        shutil.rmtree(d)
