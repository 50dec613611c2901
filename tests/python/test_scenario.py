"""redres.Scenario and redres.Result from Python: the paper's TVCMM run gives the CLI's final theta bit for bit, the
trajectory's columns are numpy views of the run (no copy), overrides act as --set does, a failed step is a status,
and bad files raise with file:line:col."""

import json
import math

import numpy as np
import pytest

import redres
from conftest import cli_run, source


@pytest.fixture(scope="module")
def tvcmm():
    return redres.Scenario.load(source("configs/paper_r_tvcmm.toml")).run()


def test_the_paper_tvcmm_run_gives_the_cli_final_theta_bit_for_bit(tvcmm, tmp_path):
    want = cli_run("configs/paper_r_tvcmm.toml", tmp_path)
    assert tvcmm.final_theta.tolist() == want["final_theta"]
    assert tvcmm.summary["manipulability"] == want["manipulability"]
    assert tvcmm.status == "ok" and tvcmm.failures == 0
    # The paper's claims on this run: the error stays below 1e-5 m, and TVCMM starts and ends at rest.
    assert tvcmm.summary["max_position_error"] < 1e-5
    assert tvcmm.summary["initial_joint_velocity_norm"] == 0.0


def test_columns_are_views_of_the_run_with_the_right_shape_and_dtype(tvcmm):
    rows = 4001
    assert tvcmm.columns[0] == "t" and "manipulability" in tvcmm
    values = tvcmm.values
    assert values.shape == (rows, len(tvcmm.columns)) and values.dtype == np.float64
    for name in ("t", "theta_1", "theta_dot_6", "manipulability", "position_error"):
        column = tvcmm[name]
        assert column.shape == (rows,) and column.dtype == np.float64, name
        assert np.shares_memory(column, values), f"{name} is a copy"
        assert not column.flags.writeable
        assert np.array_equal(column, values[:, tvcmm.columns.index(name)])
    assert tvcmm["t"][-1] == 40.0
    # The summary is the trajectory's: w(T) and the final theta are the last row.
    assert tvcmm["manipulability"][-1] == tvcmm.summary["manipulability"]["final"]
    assert np.array_equal(np.array([tvcmm[f"theta_{j}"][-1] for j in range(1, 7)]), tvcmm.final_theta)
    assert set(tvcmm.trajectory) == set(tvcmm.columns)
    with pytest.raises(KeyError, match="no column 'nope'"):
        tvcmm["nope"]


def test_a_column_outlives_its_result():
    column = redres.Scenario.load(source("configs/paper_r_fast.toml")).run()["manipulability"]
    assert column.base is not None and np.isfinite(column).all()


def test_overrides_act_as_set_does(tmp_path):
    got = redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={"objectives.1.p": 1.0}).run()
    want = cli_run("configs/paper_r_tvcmm.toml", tmp_path, "objectives.1.p=1.0")
    assert got.final_theta.tolist() == want["final_theta"]
    s = redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={"solver.engine": "newton", "step": 0.02})
    assert s.engine == "newton" and s.steps == 2000


def test_summary_has_no_nan_and_writes_like_the_cli(tvcmm, tmp_path):
    def walk(v):
        if isinstance(v, dict):
            for x in v.values():
                walk(x)
        elif isinstance(v, list):
            for x in v:
                walk(x)
        elif isinstance(v, float):
            assert math.isfinite(v)
    walk(tvcmm.summary)
    tvcmm.write(str(tmp_path / "out"))
    for f in ("trajectory.csv", "frames.csv", "summary.json"):
        assert (tmp_path / "out" / f).stat().st_size > 0, f
    written = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert written["final_theta"] == tvcmm.final_theta.tolist()


def test_a_failed_step_is_a_status_not_an_exception():
    r = redres.Scenario.load(source("configs/paper_r_fast.toml"),
                             overrides={"solver.engine": "projection", "solver.max_iterations": 1}).run()
    assert r.status == "failed_steps"
    assert r.failures > 0
    assert "max_iterations" in r.first_failure
    assert r.summary["solver"]["failures"] == r.failures


def test_bad_files_and_overrides_raise_config_error_with_their_location():
    with pytest.raises(redres.ConfigError, match=r"syntax_error\.toml:3:17: TOML syntax error"):
        redres.Scenario.load(source("tests/data/robot_corpus/syntax_error.toml"))
    with pytest.raises(redres.ConfigError, match=r"--set objectives\.1\.p:1:5: .*key 'p'"):
        redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={"objectives.1.p": "not a number"})
    with pytest.raises(redres.ConfigError, match="duration"):
        redres.Scenario.load(source("configs/paper_r_tvcmm.toml"), overrides={"duration": -1.0})
    with pytest.raises((redres.ConfigError, OSError, RuntimeError), match="no_such_file"):
        redres.Scenario.load(source("configs/no_such_file.toml"))


def test_compare_runs_every_scenario_and_tabulates_them():
    files = [source(f"configs/paper_r_{n}.toml") for n in ("tvcmm", "constant_p", "mvn")]
    cmp = redres.compare(files, jobs=2)
    assert [r.name for r in cmp.results] == ["paper_r_tvcmm", "paper_r_constant_p", "paper_r_mvn"]
    table = cmp.table()
    assert [row["scenario"] for row in table] == ["paper_r_tvcmm", "paper_r_constant_p", "paper_r_mvn"]
    # The configs' `label`s: the names the figures and the table's label column show.
    assert [row["label"] for row in table] == ["TVCMM, p = 2 sin(pi t/T)", "p = 1", "MVN (p = 0)"]
    assert [r.summary["label"] for r in cmp.results] == [row["label"] for row in table]
    assert tuple(table[0]) == redres.Comparison.columns
    # The paper's comparison: TVCMM ends with a higher w than MVN.
    assert cmp["paper_r_tvcmm"].summary["manipulability"]["final"] > cmp["paper_r_mvn"].summary["manipulability"]["final"]
    md = cmp.markdown().splitlines()
    assert len(md) == 5
    # The CLI's comparison.md headings, from the one list of columns; the table's numbers are numbers.
    assert md[0] == "| " + " | ".join(redres.Comparison.headings) + " |"
    assert "max position error (m)" in md[0] and "mean iterations" in md[0]
    assert isinstance(table[0]["max_position_error"], float) and isinstance(table[0]["failures"], int)
    assert table[0]["w_final"] == cmp["paper_r_tvcmm"].summary["manipulability"]["final"]
    with pytest.raises(redres.ConfigError):
        redres.compare([files[0], source("tests/data/robot_corpus/syntax_error.toml")])
