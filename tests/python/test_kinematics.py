"""redres.Robot from Python: the kinematics at the paper's theta(0) are the C++ values (those `redres robot --json`
prints), the arrays have the right shapes and dtype, grad w matches central differences of w, and bad input raises."""

import json

import numpy as np
import pytest

import redres
from conftest import PAPER_THETA0, cli, source


@pytest.fixture(scope="module")
def paper():
    return redres.Robot.load(source("robots/paper_pushrod_6dof.toml"))


def test_paper_theta0_gives_the_cpp_values_bit_for_bit(paper):
    p = cli("robot", source("robots/paper_pushrod_6dof.toml"), "--theta", "pi/4,pi/12,pi/12,pi/12,pi/36,pi/36", "--json")
    assert p.returncode == 0, p.stderr
    want = json.loads(p.stdout)
    k = paper.kinematics(PAPER_THETA0)
    assert np.array_equal(np.array(want["theta"]), PAPER_THETA0)
    assert np.array_equal(k.f, np.array(want["f"]))
    assert np.array_equal(k.J, np.array(want["J"]))
    assert k.w == want["manipulability"]
    assert np.array_equal(k.grad_w, np.array(want["grad_manipulability"]))
    lo, hi = paper.velocity_limits(PAPER_THETA0)
    assert np.array_equal(np.column_stack([lo, hi]), np.array([j["velocity_limits"] for j in want["joints"]]))
    # The paper's w(0) (its Fig. 5 starts there).
    assert k.w == pytest.approx(0.2341, abs=1e-4)


def test_arrays_have_the_right_shapes_and_dtype(paper):
    k = paper.kinematics(PAPER_THETA0)
    for name, shape in [("f", (2,)), ("J", (2, 6)), ("grad_w", (6,)), ("grad_mu", (6,)), ("ee_pose", (4, 4)),
                        ("theta", (6,))]:
        a = getattr(k, name)
        assert isinstance(a, np.ndarray), name
        assert a.shape == shape, name
        assert a.dtype == np.float64, name
    assert isinstance(k.w, float)
    assert len(k.link_frames) == 6 and k.link_frames[0].shape == (4, 4)
    assert paper.lower_limits.shape == (6,) and paper.upper_limits.dtype == np.float64
    assert paper.dof == 6 and paper.kind == "planar" and paper.task_names == ["x", "y"]


def test_grad_w_is_the_derivative_of_w_on_a_spatial_arm():
    robot = redres.Robot.load(source("robots/franka_panda.toml"))
    theta = robot.home + 0.1
    k = robot.kinematics(theta)
    h = 1e-6
    for j in range(robot.dof):
        e = np.zeros(robot.dof)
        e[j] = h
        fd = (robot.kinematics(theta + e).w - robot.kinematics(theta - e).w) / (2 * h)
        assert fd == pytest.approx(k.grad_w[j], rel=1e-5, abs=1e-9), j
    # J's columns are the derivative of the position.
    for j in range(robot.dof):
        e = np.zeros(robot.dof)
        e[j] = h
        fd = (robot.kinematics(theta + e).f - robot.kinematics(theta - e).f) / (2 * h)
        assert np.allclose(fd, k.J[:, j], atol=1e-8), j


def test_a_wrong_size_or_a_nan_raises_with_the_condition(paper):
    with pytest.raises(ValueError, match="expected dof = 6"):
        paper.kinematics(np.zeros(5))
    with pytest.raises(ValueError, match="finite"):
        paper.kinematics(np.array([np.nan, 0, 0, 0, 0, 0]))
    with pytest.raises(ValueError, match="expected dof = 6"):
        paper.velocity_limits(np.zeros(7))


def test_a_bad_robot_file_raises_config_error_at_file_line_col():
    with pytest.raises(redres.ConfigError, match=r"unknown_kind\.toml:\d+:\d+: .*kind"):
        redres.Robot.load(source("tests/data/robot_corpus/unknown_kind.toml"))
    with pytest.raises(redres.ConfigError) as e:
        redres.Robot.load(source("tests/data/robot_corpus/syntax_error.toml"))
    assert isinstance(e.value, ValueError)


def test_urdf_robots_load_like_their_dh_twins():
    dh = redres.Robot.load(source("robots/franka_panda.toml"))
    urdf = redres.Robot.load(source("robots/franka_panda_urdf.toml"))
    rng = np.random.default_rng(5)
    for _ in range(20):
        theta = dh.lower_limits + rng.random(7) * (dh.upper_limits - dh.lower_limits)
        a, b = dh.kinematics(theta), urdf.kinematics(theta)
        assert np.allclose(a.f, b.f, atol=1e-12) and np.allclose(a.J, b.J, atol=1e-12)
