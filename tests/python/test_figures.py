"""The figures of `redres run --plots` and `redres compare` (tools/plot_run.py): every figure a run should have is
written, is a PNG, and has the pixel size its figure size and dpi give (plot_run.py saves at 110 dpi, without
cropping); no other figure is written. Runs with a coarse step (few rows) of a planar paper config with an obstacle and
of a spatial robot with obstacles and acceleration limits, and the paper's comparison (its runs are fast; the figures
take the time)."""

import json
import math
import os
import pathlib
import struct
import subprocess
import sys

import pytest

from conftest import source

DPI = 110
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def png_size(path):
    """(width, height) from the PNG's IHDR chunk (bytes 16-24); fails when the file is no PNG."""
    head = pathlib.Path(path).read_bytes()[:24]
    assert head[:8] == PNG_SIGNATURE, f"{path} is not a PNG"
    assert head[12:16] == b"IHDR", f"{path}: no IHDR chunk first"
    return struct.unpack(">II", head[16:24])


def pixels(width_in, height_in):
    return (round(width_in * DPI), round(height_in * DPI))


def joint_panels(n):
    """The joint figures (Figs. 6, 7, accelerations): 3 columns of panels above 4 joints, else 2; 4.2 x 3 in each."""
    cols = 3 if n > 4 else 2
    return pixels(4.2 * cols, 3 * math.ceil(n / cols))


def expected_figures(n, pose=False, obstacles=False, acceleration_limits=False):
    figures = {
        "fig3_profiles.png": pixels(12, 4),
        "fig4_task.png": pixels(12, 9),
        "fig6_joint_angles.png": joint_panels(n),
        "fig7_joint_velocities.png": joint_panels(n),
        "fig9b_position_error.png": pixels(7, 5.5 if pose else 3.5),
    }
    if obstacles:
        figures["fig_collision_distances.png"] = pixels(8, 4)
    if acceleration_limits:
        figures["fig_joint_accelerations.png"] = joint_panels(n)
    return figures


def redres(*args):
    """The build's redres with this interpreter's directory first on PATH (plot_run.py runs with the python3 on
    PATH, which must have matplotlib)."""
    env = dict(os.environ, PATH=os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", ""))
    exe = os.environ.get("REDRES_CLI")
    if not exe:
        pytest.fail("REDRES_CLI is not set: run the Python tests through ctest")
    return subprocess.run([exe, *args], capture_output=True, text=True, env=env, check=False)


@pytest.fixture(autouse=True)
def needs_matplotlib():
    pytest.importorskip("matplotlib")
    pytest.importorskip("numpy")


def check_figures(out, want):
    written = {p.name: png_size(p) for p in pathlib.Path(out).glob("*.png")}
    assert sorted(written) == sorted(want), f"figures in {out}"
    for name, size in want.items():
        (w, h), (want_w, want_h) = written[name], size
        assert (w, h) == (want_w, want_h), f"{name}: {w} x {h} px, expected {want_w} x {want_h}"


def test_a_planar_run_with_an_obstacle_writes_its_figures_at_their_sizes(tmp_path):
    out = tmp_path / "planar"
    p = redres("run", source("configs/paper_r_obstacle.toml"), "--set", "step=0.05", "--out", str(out), "--plots",
               "--quiet")
    assert p.returncode == 0, p.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["robot"]["kind"] == "planar" and summary["obstacles"]
    check_figures(out, expected_figures(len(summary["robot"]["joint_names"]), obstacles=True))


def test_a_spatial_run_with_obstacles_and_acceleration_limits_writes_its_figures_at_their_sizes(tmp_path):
    out = tmp_path / "spatial"
    p = redres("run", source("configs/panda_table_pole.toml"), "--set", "step=0.05", "--out", str(out), "--plots",
               "--quiet")
    assert p.returncode == 0, p.stderr
    summary = json.loads((out / "summary.json").read_text())
    n = len(summary["robot"]["joint_names"])
    assert summary["robot"]["kind"] == "spatial" and n == 7 and summary["obstacles"]
    check_figures(out, expected_figures(n, obstacles=True, acceleration_limits=True))


def test_the_paper_comparison_writes_fig5_with_its_zoom_and_each_runs_figures(tmp_path):
    # The full runs: TVCMM and p = 1 coincide after t of about 8 s, so Fig. 5 has its zoom panel (12 x 4.8 in; one
    # panel is 8 x 4.8 in).
    out = tmp_path / "paper"
    configs = [source(f"configs/paper_r_{n}.toml") for n in ("tvcmm", "constant_p", "mvn")]
    p = redres("compare", *configs, "--out", str(out), "--quiet")
    assert p.returncode == 0, p.stderr
    assert png_size(out / "fig5_manipulability.png") == pixels(12, 4.8)
    labels = []
    for name in ("paper_r_tvcmm", "paper_r_constant_p", "paper_r_mvn"):
        check_figures(out / name, expected_figures(6))
        labels.append(json.loads((out / name / "summary.json").read_text())["label"])
    assert labels == ["TVCMM, p = 2 sin(pi t/T)", "p = 1", "MVN (p = 0)"]


def test_png_size_refuses_a_file_that_is_no_png(tmp_path):
    bogus = tmp_path / "x.png"
    bogus.write_bytes(b"GIF89a" + bytes(30))
    with pytest.raises(AssertionError):
        png_size(bogus)


def test_the_task_figure_has_a_panel_per_task_and_refuses_runs_without_tasks(tmp_path):
    # tools/plot_tasks.py over the two priority orders of the conflicting tasks (docs/tasks.md), at a coarse step.
    runs = []
    for order in ("tool_first", "elbow_first"):
        out = tmp_path / order
        p = redres("run", source(f"configs/panda_conflict_{order}.toml"), "--set", "step=0.05", "--out", str(out),
                   "--quiet")
        assert p.returncode == 0, p.stderr
        runs.append(str(out))
    tool = source("tools/plot_tasks.py")
    png = tmp_path / "tasks.png"
    p = subprocess.run([sys.executable, tool, str(png), *runs], capture_output=True, text=True, check=False)
    assert p.returncode == 0, p.stderr
    # Two panels (tool_error, elbow_error) of 8 x 2.4 in, 0.8 in for the legend, at 120 dpi.
    assert png_size(png) == (round(8 * 120), round((2 * 2.4 + 0.8) * 120))
    # A run without tasks has no task columns: a clear error, no file.
    plain = tmp_path / "plain"
    p = redres("run", source("configs/planar_4link_circle.toml"), "--set", "step=0.05", "--out", str(plain), "--quiet")
    assert p.returncode == 0, p.stderr
    none = tmp_path / "none.png"
    p = subprocess.run([sys.executable, tool, str(none), str(plain)], capture_output=True, text=True, check=False)
    assert p.returncode != 0 and "no task error columns" in p.stderr and not none.exists()
