"""The binary trajectory (--format hdf5): trajectory.h5 holds the same tables as trajectory.csv and frames.csv,
value for value (the CSV's numbers are the shortest that read back exactly), with the same column names, and the
plotter reads it."""

import json
import os
import subprocess
import sys

import h5py
import numpy as np

from conftest import cli, source


def read_csv(path):
    with open(path) as f:
        columns = f.readline().strip().split(",")
    return columns, np.atleast_2d(np.loadtxt(path, delimiter=",", skiprows=1))


def test_hdf5_holds_the_csv_tables_value_for_value(tmp_path):
    for fmt in ("csv", "hdf5"):
        p = cli("run", source("configs/paper_r_fast.toml"), "--out", str(tmp_path / fmt), "--quiet",
                "--format", fmt, "--record", "every=7")
        assert p.returncode == 0, p.stderr
    assert not (tmp_path / "hdf5" / "trajectory.csv").exists()
    assert not (tmp_path / "csv" / "trajectory.h5").exists()
    with h5py.File(tmp_path / "hdf5" / "trajectory.h5", "r") as f:
        for name in ("trajectory", "frames"):
            columns, values = read_csv(tmp_path / "csv" / f"{name}.csv")
            got = f[name][:]
            assert [c.decode() if isinstance(c, bytes) else c for c in f[name].attrs["columns"]] == columns
            assert got.dtype == np.float64
            assert got.shape == values.shape
            assert np.array_equal(got, values)
    manifest = (tmp_path / "hdf5" / ".redres-outputs").read_text()
    assert "trajectory.h5" in manifest and "trajectory.csv" not in manifest


def test_a_bad_format_is_named(tmp_path):
    p = cli("run", source("configs/paper_r_fast.toml"), "--out", str(tmp_path / "x"), "--quiet", "--format", "npy")
    assert p.returncode == 2
    assert '--format: expected "csv" or "hdf5", got "npy"' in p.stderr


def test_the_plotter_reads_the_binary_trajectory(tmp_path):
    # The plotter runs with the python3 first on PATH: this interpreter's (which has matplotlib and h5py).
    env = dict(os.environ, PATH=os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", ""))
    p = subprocess.run([os.environ["REDRES_CLI"], "run", source("configs/paper_r_fast.toml"), "--out",
                        str(tmp_path / "h"), "--quiet", "--format", "hdf5", "--plots"],
                       capture_output=True, text=True, env=env, check=False)
    assert p.returncode == 0, p.stderr
    summary = json.loads((tmp_path / "h" / "summary.json").read_text())
    assert summary["status"] == "complete"
    pngs = sorted(x.name for x in (tmp_path / "h").glob("*.png"))
    assert pngs, "no figure was written"
    for png in pngs:
        assert (tmp_path / "h" / png).stat().st_size > 10_000, png
