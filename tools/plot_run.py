#!/usr/bin/env python3
"""Renders the paper's figures from redres runs (trajectory.csv and summary.json), as PNG files.

    plot_run.py RUN_DIR                      figures of one run, written into RUN_DIR
    plot_run.py --compare DIR... --out OUT   Fig. 5 (w of every run) into OUT, and each run's figures

Per run:
  fig3_profiles.png         theta_dot and theta profiles (Fig. 3 for the p = 1 run; Fig. 4(c), (d) otherwise)
  fig4_task.png             (a) arm snapshots, (b) desired path and trajectory, (c) theta_dot, (d) theta
  fig6_joint_angles.png     each theta with its limits and its safety region
  fig7_joint_velocities.png each theta_dot with its velocity limits and the merged bounds
  fig9b_position_error.png  the position error over time
  fig_collision_distances.png  (runs with obstacle_avoidance or self_collision) the smallest distances over time,
                            with each plugin's safety and influence distances
Uses matplotlib and numpy (Debian: python3-matplotlib, python3-numpy). Exit codes: 0 figures written, 3 matplotlib
or numpy cannot be imported (with a message saying what to install), 1 or 2 any other failure.
"""
import argparse
import json
import os
import sys

# A missing library has its own exit code, so that `redres --plots` can say what to install instead of reporting a
# failed plot; the check costs nothing, as the figures need these imports anyway.
EXIT_MISSING_LIBRARY = 3
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402
    import numpy as np  # noqa: E402
except ImportError as e:
    missing = e.name if e.name in ("matplotlib", "numpy") else f"a library matplotlib needs ({e})"
    print(f"plot_run.py: {missing} is not installed for {sys.executable}: apt-get install python3-matplotlib "
          "python3-numpy (Debian's python3) or pip install matplotlib numpy", file=sys.stderr)
    sys.exit(EXIT_MISSING_LIBRARY)


def load(run_dir):
    # deletechars="": keep column names as written ("<plugin>.<column>" for a second plugin recording a quantity).
    data = np.genfromtxt(os.path.join(run_dir, "trajectory.csv"), delimiter=",", names=True, deletechars="")
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    return data, summary


def joints(summary):
    return len(summary["robot"]["joint_names"])


def profiles(ax_v, ax_q, data, n):
    t = data["t"]
    for j in range(1, n + 1):
        ax_v.plot(t, data[f"theta_dot_{j}"], label=rf"$\dot\theta_{j}$")
        ax_q.plot(t, data[f"theta_{j}"], label=rf"$\theta_{j}$")
    ax_v.set_xlabel("t (s)")
    ax_v.set_ylabel("rad/s")
    ax_q.set_xlabel("t (s)")
    ax_q.set_ylabel("rad")
    ax_v.legend(fontsize=7, ncol=2)
    ax_q.legend(fontsize=7, ncol=2)
    ax_v.grid(alpha=0.3)
    ax_q.grid(alpha=0.3)


def planar_chain(summary, theta):
    """Joint positions of a planar chain with relative joint angles."""
    lengths = summary["robot"]["link_lengths"]
    pts = [(0.0, 0.0)]
    angle = 0.0
    x = y = 0.0
    for q, length in zip(theta, lengths):
        angle += q
        x += length * np.cos(angle)
        y += length * np.sin(angle)
        pts.append((x, y))
    return np.array(pts)


def fig_task(run_dir, data, summary, n, name):
    planar = summary["robot"]["kind"] == "planar"
    fig = plt.figure(figsize=(12, 9))
    t = data["t"]
    if planar:
        ax_a = fig.add_subplot(2, 2, 1)
        for k in np.linspace(0, len(t) - 1, 25).astype(int):
            pts = planar_chain(summary, [data[f"theta_{j}"][k] for j in range(1, n + 1)])
            ax_a.plot(pts[:, 0], pts[:, 1], "-o", color="0.6", lw=0.8, ms=2)
        ax_a.plot(data["r_x"], data["r_y"], "r", lw=1.2)
        ax_a.set_aspect("equal")
        ax_a.set_title("(a) motion trajectories")
        ax_a.set_xlabel("x (m)")
        ax_a.set_ylabel("y (m)")
        ax_b = fig.add_subplot(2, 2, 2)
        ax_b.plot(data["rd_x"], data["rd_y"], "b-", lw=3, alpha=0.4, label="desired path")
        ax_b.plot(data["r_x"], data["r_y"], "r--", lw=1, label="end-effector trajectory")
        ax_b.set_aspect("equal")
        ax_b.set_xlabel("x (m)")
        ax_b.set_ylabel("y (m)")
    else:
        ax_a = fig.add_subplot(2, 2, 1, projection="3d")
        ax_a.plot(data["rd_x"], data["rd_y"], data["rd_z"], "b-", lw=3, alpha=0.4, label="desired path")
        ax_a.plot(data["r_x"], data["r_y"], data["r_z"], "r--", lw=1, label="end-effector trajectory")
        ax_a.set_title("(a) path in space")
        ax_b = fig.add_subplot(2, 2, 2)
        ax_b.plot(t, data["rd_x"] - data["rd_x"][0], label="x")
        ax_b.plot(t, data["rd_y"] - data["rd_y"][0], label="y")
        ax_b.plot(t, data["rd_z"] - data["rd_z"][0], label="z")
        ax_b.set_xlabel("t (s)")
        ax_b.set_ylabel("desired displacement (m)")
    ax_b.set_title("(b) end-effector path and trajectory")
    ax_b.legend(fontsize=8)
    profiles(fig.add_subplot(2, 2, 3), fig.add_subplot(2, 2, 4), data, n)
    fig.axes[-2].set_title(r"(c) $\dot\theta$ profiles")
    fig.axes[-1].set_title(r"(d) $\theta$ profiles")
    fig.suptitle(f"{name}: end-effector task")
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, "fig4_task.png"), dpi=110)
    plt.close(fig)


def joint_panels(run_dir, n, name, title, filename, ylabel, draw):
    """One panel per joint; draw(ax, j) plots joint j (1-based) and returns the panel title."""
    cols = 3 if n > 4 else 2
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3 * rows), squeeze=False)
    for j in range(1, n + 1):
        ax = axes[(j - 1) // cols][(j - 1) % cols]
        ax.set_title(f"({chr(96 + j)}) " + draw(ax, j), fontsize=9)
        ax.set_xlabel("t (s)")
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=6)
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].axis("off")
    fig.suptitle(f"{name}: {title}")
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, filename), dpi=110)
    plt.close(fig)


def safety_margin(summary, n):
    """The widest safety margin per joint that any plugin reports (metric `safety_margin`), else zeros."""
    margin = [0.0] * n
    for figures in summary.get("metrics", {}).values():
        m = figures.get("safety_margin")
        if m is None:
            continue
        m = m if isinstance(m, list) else [m] * n
        margin = [max(a, b) for a, b in zip(margin, m)]
    return margin


def fig_angles(run_dir, data, summary, n, name):
    lo, hi = summary["robot"]["lower_limits"], summary["robot"]["upper_limits"]
    margin = safety_margin(summary, n)
    t = data["t"]

    def draw(ax, j):
        k = j - 1
        ax.plot(t, data[f"theta_{j}"], "b", label=rf"$\theta_{j}$")
        ax.axhline(hi[k], color="r", lw=1, label=r"$\theta^\pm$")
        ax.axhline(lo[k], color="r", lw=1)
        if margin[k] > 0:
            ax.axhspan(hi[k] - margin[k], hi[k], color="r", alpha=0.15, label="safety region")
            ax.axhspan(lo[k], lo[k] + margin[k], color="r", alpha=0.15)
        return rf"$\theta_{j}$ and limits"

    joint_panels(run_dir, n, name, "joint angles, limits and safety regions", "fig6_joint_angles.png", "rad", draw)


def fig_velocities(run_dir, data, n, name):
    t = data["t"]

    def draw(ax, j):
        ax.plot(t, data[f"theta_dot_{j}"], "b", label=rf"$\dot\theta_{j}$")
        ax.plot(t, data[f"vel_hi_{j}"], "r", lw=1, label="velocity limits")
        ax.plot(t, data[f"vel_lo_{j}"], "r", lw=1)
        ax.plot(t, data[f"hi_{j}"], "g--", lw=1, label=r"bounds $\zeta^\pm$")
        ax.plot(t, data[f"lo_{j}"], "g--", lw=1)
        span = max(np.abs(data[f"vel_hi_{j}"]).max(), np.abs(data[f"vel_lo_{j}"]).max())
        ax.set_ylim(-1.1 * span, 1.1 * span)
        return rf"$\dot\theta_{j}$, limits and bounds"

    joint_panels(run_dir, n, name, "joint velocities, velocity limits and merged bounds", "fig7_joint_velocities.png",
                 "rad/s", draw)


def fig_error(run_dir, data, name):
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(data["t"], data["position_error"], "b")
    ax.set_xlabel("t (s)")
    ax.set_ylabel(r"$\|r_d - f(\theta)\|$ (m)")
    ax.set_title(f"{name}: position error (max {data['position_error'].max():.3g} m)")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, "fig9b_position_error.png"), dpi=110)
    plt.close(fig)


def fig_distances(run_dir, data, summary, name):
    """The smallest obstacle and self distances per step, with d_s and d_i of the plugin that recorded them."""
    names = data.dtype.names
    columns = [c for c in names if c.split(".")[-1] in ("min_obstacle_distance", "min_self_distance")]
    if not columns:
        return
    fig, ax = plt.subplots(figsize=(8, 4))
    metrics = summary.get("metrics", {})
    colours = ["b", "g", "m", "c"]
    for k, c in enumerate(columns):
        colour = colours[k % len(colours)]
        ax.plot(data["t"], data[c], colour, label=c)
        kind = "obstacle_avoidance" if c.endswith("min_obstacle_distance") else "self_collision"
        plugin = c.split(".")[0] if "." in c else kind
        figures = metrics.get(plugin, {})
        if "safety_distance" in figures:
            ax.axhline(figures["safety_distance"], color=colour, ls="--", lw=1, label=f"$d_s$ ({plugin})")
        if "influence_distance" in figures:
            ax.axhline(figures["influence_distance"], color=colour, ls=":", lw=1, label=f"$d_i$ ({plugin})")
    ax.axhline(0.0, color="r", lw=1, label="contact")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("distance (m)")
    ax.set_title(f"{name}: smallest collision distances")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, "fig_collision_distances.png"), dpi=110)
    plt.close(fig)


def fig_profiles(run_dir, data, n, name):
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4))
    profiles(a, b, data, n)
    a.set_title(r"(a) $\dot\theta$ profiles")
    b.set_title(r"(b) $\theta$ profiles")
    fig.suptitle(f"{name}: joint-velocity and joint-angle profiles")
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, "fig3_profiles.png"), dpi=110)
    plt.close(fig)


def plot_run(run_dir, quiet):
    data, summary = load(run_dir)
    n = joints(summary)
    name = summary.get("name", os.path.basename(os.path.normpath(run_dir)))
    fig_profiles(run_dir, data, n, name)
    fig_task(run_dir, data, summary, n, name)
    fig_angles(run_dir, data, summary, n, name)
    fig_velocities(run_dir, data, n, name)
    fig_error(run_dir, data, name)
    fig_distances(run_dir, data, summary, name)
    if not quiet:
        print(f"figures written to {run_dir}")


def plot_compare(dirs, out, quiet):
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for d in dirs:
        data, summary = load(d)
        ax.plot(data["t"], data["manipulability"], label=summary.get("name", d))
    ax.set_xlabel("t (s)")
    ax.set_ylabel(r"$w = \det(JJ^T)$")
    ax.set_title("Manipulability of the compared schemes")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.tight_layout()
    os.makedirs(out, exist_ok=True)
    fig.savefig(os.path.join(out, "fig5_manipulability.png"), dpi=110)
    plt.close(fig)
    if not quiet:
        print(f"comparison figure written to {out}")
    for d in dirs:
        plot_run(d, quiet)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run_dir", nargs="?", help="a run directory (trajectory.csv, summary.json)")
    p.add_argument("--compare", nargs="+", metavar="DIR", help="run directories to compare")
    p.add_argument("--out", help="output directory for the comparison figure")
    p.add_argument("--quiet", action="store_true")
    a = p.parse_args()
    if a.compare:
        plot_compare(a.compare, a.out or os.path.dirname(os.path.normpath(a.compare[0])), a.quiet)
    elif a.run_dir:
        plot_run(a.run_dir, a.quiet)
    else:
        p.error("give RUN_DIR or --compare DIR...")
    return 0


if __name__ == "__main__":
    sys.exit(main())
