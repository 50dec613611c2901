"""The MuJoCo plant from Python: Scenario.load(..., overrides={"plant.kind": "mujoco"}) runs the scenario on MuJoCo,
and the plant's recorded columns (measured velocities, torques, contacts, penetration) and summary figures come back
like any other column and figure, equal to the CLI's."""

import numpy as np
import pytest

import redres
from conftest import cli_run, source

pytestmark = pytest.mark.skipif(not redres.mujoco_available(), reason="redres was built without MuJoCo")


def test_the_plant_columns_and_figures_come_back_like_any_other(tmp_path):
    result = redres.Scenario.load(
        source("configs/paper_r_tvcmm.toml"), overrides={"plant.kind": "mujoco", "plant.kv": 20.0}
    ).run()
    for j in range(1, 7):
        assert f"torque_{j}" in result.columns and f"measured_theta_dot_{j}" in result.columns
    assert "contacts" in result.columns and "penetration" in result.columns
    assert result.summary["plant"]["kind"] == "mujoco"
    assert result.summary["plant"]["max_contacts"] == 0
    # The recorded torques are the summary's, and the measured velocities are not the commands.
    for j in range(6):
        assert np.max(np.abs(result[f"torque_{j + 1}"])) <= result.summary["plant"]["max_torque"][j]
    assert not np.array_equal(result["measured_theta_dot_2"], result["theta_dot_2"])
    assert result.summary["max_position_error"] < 1e-3
    # The same run from the CLI: the same final angles.
    want = cli_run("configs/paper_r_mujoco.toml", tmp_path)
    assert result.final_theta.tolist() == want["final_theta"]
