#!/usr/bin/env python3
"""Renders the paper's figures from redres runs (trajectory.csv and summary.json), as PNG files.

    plot_run.py RUN_DIR                      figures of one run, written into RUN_DIR
    plot_run.py --animate RUN_DIR            an animation of the arm and the obstacles, written into RUN_DIR
    plot_run.py --compare DIR... --out OUT   Fig. 5 (w of every run) into OUT, and each run's figures

Per run:
  fig3_profiles.png         theta_dot and theta profiles (Fig. 3 for the p = 1 run; Fig. 4(c), (d) otherwise)
  fig4_task.png             (a) arm snapshots with the obstacles (planar: their cross-sections with the plane z = 0;
                            spatial: 3-D), the arm at its closest approach to an obstacle highlighted with its
                            collision shapes, (b) desired path and trajectory, (c) theta_dot, (d) theta
  fig6_joint_angles.png     each theta with its limits and its safety region
  fig7_joint_velocities.png each theta_dot with its velocity limits and the merged bounds
  fig_joint_accelerations.png  (robots with acceleration limits) each commanded theta_ddot with its limits
  fig9b_position_error.png  the position error over time (and the orientation error, for pose tasks)
  fig_collision_distances.png  (runs with obstacle_avoidance or self_collision) the smallest distances over time,
                            with each plugin's safety and influence distances
With --animate: animation.mp4 (H.264 by ffmpeg) when ffmpeg is on PATH, else animation.gif (Pillow): the arm (and
its collision shapes when there are obstacles), the obstacles where they are at each time, the end-effector trail and
the desired path; about ANIMATION_FPS frames per second of the run, at least MIN_ANIMATION_FRAMES (or every row of
frames.csv) and at most MAX_ANIMATION_FRAMES. The frames are drawn by blitting (the still parts once), so a short run
takes a few seconds.

The arm is drawn from frames.csv (joint frames computed by redres, so no kinematics here) and the obstacles and link
shapes from summary.json (docs/output_formats.md). Uses matplotlib and numpy (Debian: python3-matplotlib,
python3-numpy; matplotlib brings Pillow, python3-pil, which the GIF needs). Exit codes: 0 written, 3 matplotlib or
numpy cannot be imported (with a message saying what to install), 1 or 2 any other failure.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

from redres_output import OutputError, save_output  # noqa: E402  (beside this script)

# A missing library has its own exit code, so that `redres --plots` can say what to install instead of reporting a
# failed plot; the check costs nothing, as the figures need these imports anyway.
EXIT_MISSING_LIBRARY = 3
MAX_ANIMATION_FRAMES = 240
MIN_ANIMATION_FRAMES = 30
ANIMATION_FPS = 12
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.patches  # noqa: E402
    import matplotlib.pyplot as plt  # noqa: E402
    import numpy as np  # noqa: E402
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402
except ImportError as e:
    missing = e.name if e.name in ("matplotlib", "numpy") else f"a library matplotlib needs ({e})"
    print(f"plot_run.py: {missing} is not installed for {sys.executable}: apt-get install python3-matplotlib "
          "python3-numpy (Debian's python3) or pip install matplotlib numpy", file=sys.stderr)
    sys.exit(EXIT_MISSING_LIBRARY)


def read_table(run_dir, name):
    """The run's table `name` ("trajectory" or "frames") as a structured array with named columns: from NAME.csv, or,
    for a run recorded with --format hdf5, from trajectory.h5's dataset NAME (h5py). None when the run has neither."""
    csv = os.path.join(run_dir, name + ".csv")
    if os.path.exists(csv):
        # deletechars="": keep column names as written ("<plugin>.<column>" for a second plugin recording a quantity).
        return np.atleast_1d(np.genfromtxt(csv, delimiter=",", names=True, deletechars=""))
    h5 = os.path.join(run_dir, "trajectory.h5")
    if not os.path.exists(h5):
        return None
    try:
        import h5py
    except ImportError:
        print(f"plot_run.py: {h5} needs h5py for {sys.executable}: apt-get install python3-h5py", file=sys.stderr)
        sys.exit(EXIT_MISSING_LIBRARY)
    with h5py.File(h5, "r") as f:
        if name not in f:
            return None
        values = f[name][:]
        columns = [c.decode() if isinstance(c, bytes) else str(c) for c in f[name].attrs["columns"]]
    out = np.zeros(values.shape[0], dtype=[(c, "f8") for c in columns])
    for k, c in enumerate(columns):
        out[c] = values[:, k]
    return out


def load(run_dir):
    data = read_table(run_dir, "trajectory")
    if data is None:
        raise SystemExit(f"plot_run.py: no trajectory.csv or trajectory.h5 in {run_dir}")
    with open(os.path.join(run_dir, "summary.json")) as f:
        summary = json.load(f)
    return data, summary


def joints(summary):
    return len(summary["robot"]["joint_names"])


def legend_outside(ax, where="right", ncol=None, fontsize=8):
    """The axes' legend outside its data: to the right of the axes, or below them (under the x label); tight_layout
    keeps room for it. None when nothing is labelled."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    if where == "below":
        return ax.legend(handles, labels, loc="upper center", bbox_to_anchor=(0.5, -0.14), fontsize=fontsize,
                         ncol=ncol or min(len(handles), 3), frameon=False)
    return ax.legend(handles, labels, loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize=fontsize,
                     ncol=ncol or max(1, -(-len(handles) // 14)), frameon=False, handlelength=1.5)


def shared_legend(fig, axes, ncol=None, fontsize=9):
    """One legend for the whole figure, below every panel, of the distinct labels of `axes`; returns the figure
    fraction it takes at the bottom (for tight_layout's rect)."""
    entries = {}
    for ax in axes:
        for h, label in zip(*ax.get_legend_handles_labels()):
            entries.setdefault(label, h)
    if not entries:
        return 0.0
    legend = fig.legend(list(entries.values()), list(entries.keys()), loc="lower center", fontsize=fontsize,
                        ncol=ncol or min(len(entries), 4), frameon=False, bbox_to_anchor=(0.5, 0.0))
    fig.canvas.draw()
    return float(legend.get_window_extent().height / fig.bbox.height) + 0.01


def run_name(summary, run_dir):
    """The run's name in titles and legends: summary.json's label (the scenario's `label`, default its name)."""
    return summary.get("label") or summary.get("name") or os.path.basename(os.path.normpath(run_dir))


def profiles(ax_v, ax_q, data, n):
    t = data["t"]
    for j in range(1, n + 1):
        ax_v.plot(t, data[f"theta_dot_{j}"], label=rf"$\dot\theta_{j}$")
        ax_q.plot(t, data[f"theta_{j}"], label=rf"$\theta_{j}$")
    ax_v.set_xlabel("t (s)")
    ax_v.set_ylabel("rad/s")
    ax_q.set_xlabel("t (s)")
    ax_q.set_ylabel("rad")
    legend_outside(ax_v)
    legend_outside(ax_q)
    ax_v.grid(alpha=0.3)
    ax_q.grid(alpha=0.3)


def load_frames(run_dir, summary):
    """frames.csv as (t, points, rotations): points (rows, n + 2, 3) is the base origin (summary.json's
    robot.base_position), the n joint frames' origins and the end effector; rotations (rows, n, 3, 3) the joint
    frames' rotations. None for a run without the file."""
    f = read_table(run_dir, "frames")
    if f is None:
        return None
    n = sum(1 for c in f.dtype.names if c.startswith("joint_") and c.endswith("_x"))
    rows = len(f)
    points = np.zeros((rows, n + 2, 3))
    rotations = np.zeros((rows, n, 3, 3))
    points[:, 0] = summary["robot"].get("base_position", [0.0, 0.0, 0.0])
    for j in range(1, n + 1):
        points[:, j] = np.column_stack([f[f"joint_{j}_{a}"] for a in "xyz"])
        for a in range(3):
            for b in range(3):
                rotations[:, j - 1, a, b] = f[f"joint_{j}_r{a + 1}{b + 1}"]
    points[:, n + 1] = np.column_stack([f[f"ee_{a}"] for a in "xyz"])
    return f["t"], points, rotations


def obstacles(summary):
    return summary.get("obstacles", [])


def moving(obstacle):
    return any(v != 0.0 for v in obstacle.get("velocity", [0.0, 0.0, 0.0]))


def obstacle_pose(obstacle, t):
    """World position and rotation of an obstacle at time t: p(t) = p0 + v t, rotation fixed."""
    p = np.array(obstacle["position"]) + t * np.array(obstacle.get("velocity", [0.0, 0.0, 0.0]))
    return p, np.array(obstacle["rotation"])


def link_shape_poses(summary, rotations_k, points_k):
    """(shape, world position, world rotation) of every link collision shape at one row of frames.csv."""
    out = []
    for shape in summary["robot"].get("link_shapes", []):
        j = shape["joint"] - 1
        Rj, oj = rotations_k[j], points_k[j + 1]
        out.append((shape, oj + Rj @ np.array(shape["position"]), Rj @ np.array(shape["rotation"])))
    return out


def bounding_radius(shape):
    kind = shape["shape"]
    if kind in ("points", "octree"):
        cells = np.array(shape.get("cells", [[0.0, 0.0, 0.0, 0.0]]), dtype=float).reshape(-1, 4)
        return float(np.max(np.linalg.norm(cells[:, :3], axis=1) + cells[:, 3])) + shape.get("radius", 0.0)
    if kind == "sphere":
        return shape["radius"]
    if kind == "capsule":
        return shape["radius"] + 0.5 * shape["length"]
    if kind == "cylinder":
        return float(np.hypot(shape["radius"], 0.5 * shape["length"]))
    return 0.5 * float(np.linalg.norm(shape["size"]))


def inside(shape, q):
    """Whether local points q (..., 3) lie in the shape (centred on its pose; axis along local z)."""
    kind = shape["shape"]
    if kind == "sphere":
        return np.linalg.norm(q, axis=-1) <= shape["radius"]
    if kind == "capsule":
        h = 0.5 * shape["length"]
        d = q.copy()
        d[..., 2] = q[..., 2] - np.clip(q[..., 2], -h, h)
        return np.linalg.norm(d, axis=-1) <= shape["radius"]
    if kind == "cylinder":
        return (np.abs(q[..., 2]) <= 0.5 * shape["length"]) & (np.hypot(q[..., 0], q[..., 1]) <= shape["radius"])
    return np.all(np.abs(q) <= 0.5 * np.array(shape["size"]), axis=-1)


def plane_section(shape, p, R, directions=120):
    """The shape's cross-section with the plane z = 0 as a polygon (directions x 2), found along rays from the
    centre's projection (the sections are convex); None when that point is not inside the shape."""
    c = np.array([p[0], p[1], 0.0])
    if not inside(shape, R.T @ (c - p)):
        return None
    a = np.linspace(0.0, 2.0 * np.pi, directions, endpoint=False)
    d = np.column_stack([np.cos(a), np.sin(a), np.zeros_like(a)])
    lo = np.zeros(directions)
    hi = np.full(directions, 2.0 * bounding_radius(shape) + 1e-9)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        ok = inside(shape, (c + mid[:, None] * d - p) @ R)
        lo = np.where(ok, mid, lo)
        hi = np.where(ok, hi, mid)
    return c[:2] + lo[:, None] * d[:, :2]


def surface(shape, p, R):
    """A 3-D mesh of the shape at world pose (p, R): (X, Y, Z) grids, or for a box a list of its 6 faces (a convex
    hull is drawn as the box of its vertices, which summary.json gives as its `size`)."""
    kind = shape["shape"]
    if kind in ("box", "convex"):
        h = 0.5 * np.array(shape["size"])
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * h @ R.T + p
        faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
        return [corners[f] for f in faces]
    r = shape["radius"]
    h = 0.5 * shape.get("length", 0.0)
    if kind == "sphere":
        v = np.linspace(0.0, np.pi, 13)
        rho, z = r * np.sin(v), r * np.cos(v)
    elif kind == "capsule":
        v1, v2 = np.linspace(0.0, np.pi / 2, 7), np.linspace(np.pi / 2, np.pi, 7)
        rho = r * np.sin(np.concatenate([v1, v2]))
        z = np.concatenate([r * np.cos(v1) + h, r * np.cos(v2) - h])
    else:
        rho, z = np.array([0.0, r, r, 0.0]), np.array([h, h, -h, -h])
    u = np.linspace(0.0, 2.0 * np.pi, 21)
    local = np.stack([np.outer(rho, np.cos(u)), np.outer(rho, np.sin(u)), np.outer(z, np.ones_like(u))], axis=-1)
    world = local @ R.T + p
    return world[..., 0], world[..., 1], world[..., 2]


def is_cloud(shape):
    return shape["shape"] in ("points", "octree")


def cloud_cells(shape, p, R):
    """A cloud obstacle's occupied cells (as summary.json lists them, at most a few thousand): world centres, edges."""
    cells = np.array(shape.get("cells", []), dtype=float).reshape(-1, 4)
    return cells[:, :3] @ R.T + p, cells[:, 3]


def draw_section(ax, shape, p, R, **style):
    """The shape's z = 0 section as a filled patch on 2-D axes; the patch, or None when it misses the plane."""
    if is_cloud(shape):
        centres, edges = cloud_cells(shape, p, R)
        near = np.abs(centres[:, 2]) <= 0.5 * edges + shape.get("radius", 0.0)
        if not near.any():
            return None
        return ax.scatter(centres[near, 0], centres[near, 1], s=2, marker="s", color=style.get("facecolor", "grey"),
                          label=style.get("label"))
    poly = plane_section(shape, p, R)
    if poly is None:
        return None
    patch = matplotlib.patches.Polygon(poly, closed=True, **style)
    ax.add_patch(patch)
    return patch


def draw_solid(ax, shape, p, R, color, alpha):
    """The shape on 3-D axes; the artists drawn."""
    if is_cloud(shape):
        centres, _ = cloud_cells(shape, p, R)
        return [ax.scatter(centres[:, 0], centres[:, 1], centres[:, 2], s=1, color=color, alpha=max(alpha, 0.3),
                           depthshade=False)]
    mesh = surface(shape, p, R)
    if isinstance(mesh, list):
        faces = Poly3DCollection(mesh, facecolor=color, edgecolor=color, alpha=alpha, linewidth=0.5)
        ax.add_collection3d(faces)
        return [faces]
    return [ax.plot_surface(*mesh, color=color, alpha=alpha, linewidth=0, shade=True)]


def closest_approach(data, frames_t):
    """(frames row, t, distance) of the smallest obstacle distance recorded, or None without one."""
    columns = [c for c in data.dtype.names if c.split(".")[-1] == "min_obstacle_distance"]
    if not columns:
        return None
    d = np.min(np.column_stack([data[c] for c in columns]), axis=1)
    if not np.isfinite(d).any():
        return None
    k = int(np.nanargmin(np.where(np.isfinite(d), d, np.nan)))
    row = int(np.argmin(np.abs(frames_t - data["t"][k])))
    return row, float(data["t"][k]), float(d[k])


def obstacle_times(summary, duration, count=5):
    """Times at which to draw the obstacles in a still figure: t = 0 only, unless one moves."""
    if any(moving(o) for o in obstacles(summary)):
        return np.linspace(0.0, duration, count)
    return np.array([0.0])


def equal_3d(ax, points):
    """Equal scales on 3-D axes around the given points (k x 3)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = 0.5 * (lo + hi), 0.5 * max(float((hi - lo).max()), 1e-3) * 1.05
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")


def scene_points(summary, frames, duration):
    """Points that the scene covers over the run (arm, obstacles' extents), for fixed 3-D limits."""
    pts = [frames[1].reshape(-1, 3)]
    for o in obstacles(summary):
        for t in (0.0, duration):
            p, R = obstacle_pose(o, t)
            if is_cloud(o):
                pts.append(cloud_cells(o, p, R)[0])
            else:
                r = bounding_radius(o)
                pts.append(np.array([p - r, p + r]))
    return np.vstack(pts)


OBSTACLE_COLOUR = "tab:orange"
CLOSEST_COLOUR = "tab:blue"


def snapshot_planar(ax, data, summary, frames, duration):
    t_f, pts, rots = frames
    for k in np.unique(np.linspace(0, len(t_f) - 1, 25).round().astype(int)):
        ax.plot(pts[k, :, 0], pts[k, :, 1], "-o", color="0.6", lw=0.8, ms=2)
    ax.plot(data["r_x"], data["r_y"], "r", lw=1.2, label="end-effector trajectory")
    times = obstacle_times(summary, duration)
    for i, t in enumerate(times):
        alpha = 0.7 if len(times) == 1 else 0.15 + 0.55 * i / (len(times) - 1)
        for o in obstacles(summary):
            p, R = obstacle_pose(o, t)
            patch = draw_section(ax, o, p, R, facecolor=OBSTACLE_COLOUR, edgecolor="k", lw=0.6, alpha=alpha)
            if patch is not None and i in (0, len(times) - 1) and len(times) > 1 and moving(o):
                ax.annotate(f"t = {t:.3g} s", p[:2], xytext=(0, -12 if i == 0 else 12), textcoords="offset points",
                            fontsize=6, ha="center", va="center")
    if obstacles(summary):
        ax.plot([], [], "s", color=OBSTACLE_COLOUR, label="obstacles (faded: earlier)" if len(times) > 1
                else "obstacles")
    closest = closest_approach(data, t_f)
    if closest is not None:
        k, t, d = closest
        for shape, p, R in link_shape_poses(summary, rots[k], pts[k]):
            draw_section(ax, shape, p, R, facecolor=CLOSEST_COLOUR, edgecolor=CLOSEST_COLOUR, lw=0.5, alpha=0.25)
        for o in obstacles(summary):
            if moving(o):
                p, R = obstacle_pose(o, t_f[k])
                draw_section(ax, o, p, R, facecolor="none", edgecolor=CLOSEST_COLOUR, lw=1.0)
        ax.plot(pts[k, :, 0], pts[k, :, 1], "-o", color=CLOSEST_COLOUR, lw=1.5, ms=3,
                label=f"closest approach (t = {t:.2f} s)")
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    legend_outside(ax, "below", ncol=2)


def zoom_closest(ax, summary, frames, closest):
    """The arm's collision shapes and the obstacle nearest to them at the closest approach, zoomed (planar)."""
    t_f, pts, rots = frames
    k, t, d = closest
    links = link_shape_poses(summary, rots[k], pts[k])
    link_radius = max([sh["radius"] for sh, _, _ in links if "radius" in sh] or [0.0])

    def anchors(o):  # the obstacle's centre, or a cloud's cell centres (world)
        p, R = obstacle_pose(o, t_f[k])
        return cloud_cells(o, p, R)[0] if is_cloud(o) else p[None, :]

    def gaps(o):  # each anchor's distance to the nearest joint segment
        q = anchors(o)
        a, b = pts[k, :-1], pts[k, 1:]
        ab = b - a
        s = np.clip(np.einsum("mij,ij->mi", q[:, None, :] - a[None], ab) / np.maximum(np.einsum("ij,ij->i", ab, ab),
                                                                                     1e-18), 0.0, 1.0)
        return np.min(np.linalg.norm(a[None] + s[..., None] * ab[None] - q[:, None, :], axis=2), axis=1)

    nearest = min(obstacles(summary), key=lambda o: float(np.min(gaps(o))))
    if is_cloud(nearest):  # zoom on the cell nearest the arm
        centre = anchors(nearest)[int(np.argmin(gaps(nearest)))]
        half = 1.5 * (0.05 + link_radius + max(d, 0.0)) + 0.01
    else:
        centre, _ = obstacle_pose(nearest, t_f[k])
        half = 1.5 * (bounding_radius(nearest) + link_radius + max(d, 0.0)) + 0.01
    for o in obstacles(summary):
        draw_section(ax, o, *obstacle_pose(o, t_f[k]), facecolor=OBSTACLE_COLOUR, edgecolor="k", lw=0.8, alpha=0.8)
    for shape, p, R in links:
        draw_section(ax, shape, p, R, facecolor=CLOSEST_COLOUR, edgecolor=CLOSEST_COLOUR, lw=0.8, alpha=0.3)
    ax.plot(pts[k, :, 0], pts[k, :, 1], "-o", color=CLOSEST_COLOUR, lw=1.5, ms=4)
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"(a') closest approach, t = {t:.2f} s:\nlinks' collision shapes {d * 1000:.1f} mm from the obstacle",
                 fontsize=10)


def snapshot_spatial(ax, data, summary, frames, duration):
    t_f, pts, rots = frames
    ax.plot(data["rd_x"], data["rd_y"], data["rd_z"], "b-", lw=3, alpha=0.4, label="desired path")
    ax.plot(data["r_x"], data["r_y"], data["r_z"], "r--", lw=1, label="end-effector trajectory")
    snaps = np.unique(np.linspace(0, len(t_f) - 1, 8).round().astype(int))
    for i, k in enumerate(snaps):
        last = i == len(snaps) - 1
        ax.plot(pts[k, :, 0], pts[k, :, 1], pts[k, :, 2], "-o", color="k" if last else "0.5",
                alpha=1.0 if last else 0.25 + 0.5 * i / max(len(snaps) - 1, 1), lw=2 if last else 1, ms=3,
                label="arm at t = T (grey: earlier)" if last else None)
    times = obstacle_times(summary, duration, 3)
    for i, t in enumerate(times):
        alpha = 0.5 if len(times) == 1 else 0.15 + 0.35 * i / (len(times) - 1)
        for o in obstacles(summary):
            draw_solid(ax, o, *obstacle_pose(o, t), OBSTACLE_COLOUR, alpha)
    closest = closest_approach(data, t_f)
    if closest is not None:
        k, t, d = closest
        for shape, p, R in link_shape_poses(summary, rots[k], pts[k]):
            if shape["shape"] in ("box", "convex"):
                draw_solid(ax, shape, p, R, CLOSEST_COLOUR, 0.2)
            else:
                ax.plot_wireframe(*surface(shape, p, R), color=CLOSEST_COLOUR, lw=0.3, alpha=0.5)
        ax.plot(pts[k, :, 0], pts[k, :, 1], pts[k, :, 2], "-o", color=CLOSEST_COLOUR, lw=2, ms=3,
                label=f"closest approach: t = {t:.2f} s, d = {d * 1000:.1f} mm")
    equal_3d(ax, np.vstack([scene_points(summary, frames, duration),
                            np.column_stack([data["rd_x"], data["rd_y"], data["rd_z"]])]))
    legend_outside(ax, "below", ncol=2)


def fig_task(run_dir, data, summary, frames, n, name):
    planar = summary["robot"]["kind"] == "planar"
    fig = plt.figure(figsize=(12, 9))
    t = data["t"]
    duration = float(t[-1])
    # A planar run that came close to an obstacle gets a third panel in the top row: the closest approach, zoomed.
    closest = closest_approach(data, frames[0]) if planar and frames is not None and obstacles(summary) else None
    grid = fig.add_gridspec(2, 6)
    top = [grid[0, 0:2], grid[0, 2:4], grid[0, 4:6]] if closest else [grid[0, 0:3], grid[0, 3:6]]
    if planar:
        ax_a = fig.add_subplot(top[0])
        if frames is not None:
            snapshot_planar(ax_a, data, summary, frames, duration)
        else:
            ax_a.plot(data["r_x"], data["r_y"], "r", lw=1.2)
            ax_a.set_aspect("equal")
            ax_a.text(0.5, 0.02, "no frames.csv in this run: no arm drawn", transform=ax_a.transAxes, ha="center",
                      fontsize=7)
        ax_a.set_title("(a) motion trajectories")
        if closest:
            zoom_closest(fig.add_subplot(top[1]), summary, frames, closest)
        ax_b = fig.add_subplot(top[-1])
        ax_b.plot(data["rd_x"], data["rd_y"], "b-", lw=3, alpha=0.4, label="desired path")
        ax_b.plot(data["r_x"], data["r_y"], "r--", lw=1, label="end-effector trajectory")
        ax_b.set_aspect("equal")
        ax_b.set_xlabel("x (m)")
        ax_b.set_ylabel("y (m)")
    else:
        ax_a = fig.add_subplot(top[0], projection="3d")
        if frames is not None:
            snapshot_spatial(ax_a, data, summary, frames, duration)
            ax_a.set_title("(a) arm snapshots and path")
        else:
            ax_a.plot(data["rd_x"], data["rd_y"], data["rd_z"], "b-", lw=3, alpha=0.4, label="desired path")
            ax_a.plot(data["r_x"], data["r_y"], data["r_z"], "r--", lw=1, label="end-effector trajectory")
            ax_a.set_title("(a) path in space (no frames.csv: no arm drawn)")
        ax_b = fig.add_subplot(top[-1])
        ax_b.plot(t, data["rd_x"] - data["rd_x"][0], label="x")
        ax_b.plot(t, data["rd_y"] - data["rd_y"][0], label="y")
        ax_b.plot(t, data["rd_z"] - data["rd_z"][0], label="z")
        ax_b.set_xlabel("t (s)")
        ax_b.set_ylabel("desired displacement (m)")
    ax_b.set_title("(b) end-effector path and trajectory")
    legend_outside(ax_b, "below", fontsize=8)
    ax_c, ax_d = fig.add_subplot(grid[1, 0:3]), fig.add_subplot(grid[1, 3:6])
    profiles(ax_c, ax_d, data, n)
    ax_c.set_title(r"(c) $\dot\theta$ profiles")
    ax_d.set_title(r"(d) $\theta$ profiles")
    fig.suptitle(f"{name}: end-effector task")
    fig.tight_layout()
    save_output(os.path.join(run_dir, "fig4_task.png"), lambda target: fig.savefig(target, dpi=110))
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
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].axis("off")
    fig.suptitle(f"{name}: {title}")
    # One legend for every panel, below them (the panels' titles name the joint).
    bottom = shared_legend(fig, [ax for row in axes for ax in row])
    fig.tight_layout(rect=(0, bottom, 1, 1))
    save_output(os.path.join(run_dir, filename), lambda target: fig.savefig(target, dpi=110))
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
        ax.plot(t, data[f"theta_{j}"], "b", label=r"joint angle $\theta_j$")
        ax.axhline(hi[k], color="r", lw=1, label=r"joint limits $\theta_j^\pm$")
        ax.axhline(lo[k], color="r", lw=1)
        if margin[k] > 0:
            ax.axhspan(hi[k] - margin[k], hi[k], color="r", alpha=0.15, label="safety regions")
            ax.axhspan(lo[k], lo[k] + margin[k], color="r", alpha=0.15)
        return rf"$\theta_{j}$ and limits"

    joint_panels(run_dir, n, name, "joint angles, limits and safety regions", "fig6_joint_angles.png", "rad", draw)


def fig_velocities(run_dir, data, n, name):
    t = data["t"]

    def draw(ax, j):
        ax.plot(t, data[f"theta_dot_{j}"], "b", label=r"joint velocity $\dot\theta_j$")
        ax.plot(t, data[f"vel_hi_{j}"], "r", lw=1, label="velocity limits")
        ax.plot(t, data[f"vel_lo_{j}"], "r", lw=1)
        ax.plot(t, data[f"hi_{j}"], "g--", lw=1, label=r"merged bounds $\zeta^\pm$")
        ax.plot(t, data[f"lo_{j}"], "g--", lw=1)
        span = max(np.abs(data[f"vel_hi_{j}"]).max(), np.abs(data[f"vel_lo_{j}"]).max())
        ax.set_ylim(-1.1 * span, 1.1 * span)
        return rf"$\dot\theta_{j}$, limits and bounds"

    joint_panels(run_dir, n, name, "joint velocities, velocity limits and merged bounds", "fig7_joint_velocities.png",
                 "rad/s", draw)


def fig_accelerations(run_dir, data, n, name):
    """The commanded accelerations (theta_ddot_j) against the robot's acceleration limits (acc_lo_j, acc_hi_j), for
    robots that give them; runs of other robots, and runs of redres before it recorded theta_ddot, draw nothing."""
    columns = data.dtype.names
    if "theta_ddot_1" not in columns or "acc_hi_1" not in columns:
        return
    t = data["t"]

    def draw(ax, j):
        ax.plot(t, data[f"theta_ddot_{j}"], "b", lw=0.8, label=r"commanded joint acceleration $\ddot\theta_j$")
        ax.plot(t, data[f"acc_hi_{j}"], "r", lw=1, label="acceleration limits")
        ax.plot(t, data[f"acc_lo_{j}"], "r", lw=1)
        span = max(np.abs(data[f"acc_hi_{j}"]).max(), np.abs(data[f"acc_lo_{j}"]).max())
        ax.set_ylim(-1.15 * span, 1.15 * span)
        return rf"$\ddot\theta_{j}$ and limits"

    joint_panels(run_dir, n, name, "commanded joint accelerations and acceleration limits", "fig_joint_accelerations.png",
                 "rad/s$^2$", draw)


def fig_error(run_dir, data, name):
    """The position error, and for pose tasks the orientation error (the angle of R_d R') below it."""
    pose = "orientation_error" in data.dtype.names
    fig, axes = plt.subplots(2 if pose else 1, 1, figsize=(7, 5.5 if pose else 3.5), sharex=True, squeeze=False)
    ax = axes[0][0]
    ax.plot(data["t"], data["position_error"], "b")
    ax.set_ylabel(r"$\|r_d - f(\theta)\|$ (m)")
    ax.set_title(f"{name}: position error (max {data['position_error'].max():.3g} m)")
    ax.grid(alpha=0.3)
    if pose:
        ax2 = axes[1][0]
        ax2.plot(data["t"], data["orientation_error"], "r")
        ax2.set_ylabel("orientation error (rad)")
        ax2.set_title(f"orientation error (max {data['orientation_error'].max():.3g} rad)")
        ax2.grid(alpha=0.3)
    axes[-1][0].set_xlabel("t (s)")
    fig.tight_layout()
    save_output(os.path.join(run_dir, "fig9b_position_error.png"), lambda target: fig.savefig(target, dpi=110))
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
    legend_outside(ax)
    fig.tight_layout()
    save_output(os.path.join(run_dir, "fig_collision_distances.png"), lambda target: fig.savefig(target, dpi=110))
    plt.close(fig)


def fig_plant(run_dir, data, summary, n, name):
    """A run on the MuJoCo plant: per joint, the commanded and the measured joint velocity (top row) and the torque
    against the effort limit (bottom row); and the position error under dynamics beside the kinematic plant's."""
    plant = summary.get("plant", {})
    if plant.get("kind") != "mujoco" or "torque_1" not in data.dtype.names:
        return
    t = data["t"]
    fig, axes = plt.subplots(3, n, figsize=(2.6 * n, 7.5), squeeze=False)
    limits = plant.get("effort_limit", [0.0] * n)
    for j in range(1, n + 1):
        ax = axes[0][j - 1]
        ax.plot(t, data[f"theta_dot_{j}"], "b", lw=1, label="commanded")
        ax.plot(t, data[f"measured_theta_dot_{j}"], "r--", lw=1, label="measured")
        ax.set_title(f"joint {j}", fontsize=9)
        ax.grid(alpha=0.3)
        ax = axes[1][j - 1]
        ax.plot(t, data[f"torque_{j}"], "k", lw=1, label="torque")
        limit = limits[j - 1] if j - 1 < len(limits) else 0.0
        if limit > 0.0:
            ax.axhline(limit, color="r", ls="--", lw=1, label="effort limit")
            ax.axhline(-limit, color="r", ls="--", lw=1)
        ax.set_xlabel("t (s)", fontsize=8)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel(r"$\dot\theta$ (rad/s)")
    axes[1][0].set_ylabel("torque (N m)")
    for ax in axes[2]:
        ax.remove()
    err = fig.add_subplot(3, 1, 3)
    err.plot(t, data["position_error"], "b", lw=1, label="MuJoCo plant")
    err.axhline(plant.get("kinematic_max_position_error", 0.0), color="g", ls="--", lw=1,
                label="kinematic plant's largest")
    if "contacts" in data.dtype.names and data["contacts"].max() > 0:
        first = plant.get("first_contact_time", -1.0)
        err.axvline(first, color="r", lw=1, label=f"first contact (t = {first:.3g} s)")
    err.set_xlabel("t (s)")
    err.set_ylabel("position error (m)")
    err.set_yscale("log" if data["position_error"].max() > 0 else "linear")
    err.grid(alpha=0.3)
    legend_outside(err)
    ratio = plant.get("max_torque_ratio", 0.0)
    torques = (f"torques (max {100 * ratio:.0f} % of the limit)" if any(x > 0.0 for x in limits)
               else "torques (the robot gives no effort limits)")
    fig.suptitle(f"{name} on MuJoCo ({plant.get('actuator', '')}): velocities, {torques}, "
                 f"at most {plant.get('max_contacts', 0)} contact(s) at once", wrap=True)
    bottom = shared_legend(fig, [axes[0][0], axes[1][0]], fontsize=8)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    save_output(os.path.join(run_dir, "fig_plant.png"), lambda target: fig.savefig(target, dpi=110))
    plt.close(fig)


def fig_profiles(run_dir, data, n, name):
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4))
    profiles(a, b, data, n)
    a.set_title(r"(a) $\dot\theta$ profiles")
    b.set_title(r"(b) $\theta$ profiles")
    fig.suptitle(f"{name}: joint-velocity and joint-angle profiles")
    fig.tight_layout()
    save_output(os.path.join(run_dir, "fig3_profiles.png"), lambda target: fig.savefig(target, dpi=110))
    plt.close(fig)


def plot_run(run_dir, quiet):
    data, summary = load(run_dir)
    n = joints(summary)
    name = run_name(summary, run_dir)
    fig_profiles(run_dir, data, n, name)
    fig_task(run_dir, data, summary, load_frames(run_dir, summary), n, name)
    fig_angles(run_dir, data, summary, n, name)
    fig_velocities(run_dir, data, n, name)
    fig_accelerations(run_dir, data, n, name)
    fig_error(run_dir, data, name)
    fig_distances(run_dir, data, summary, name)
    fig_plant(run_dir, data, summary, n, name)
    if not quiet:
        print(f"figures written to {run_dir}")


def animation_rows(t_f, duration):
    """The rows of frames.csv that become frames, and the frame rate: about ANIMATION_FPS frames per second of the run
    (real time), at least MIN_ANIMATION_FRAMES (or every row, when there are fewer) and at most MAX_ANIMATION_FRAMES
    (longer runs play faster, never below 4 frames per second)."""
    wanted = int(np.clip(round(ANIMATION_FPS * duration), MIN_ANIMATION_FRAMES, MAX_ANIMATION_FRAMES))
    rows = np.unique(np.linspace(0, len(t_f) - 1, min(len(t_f), wanted)).round().astype(int))
    fps = int(np.clip(round(len(rows) / max(duration, 1e-9)), 4, 25)) if duration > 0 else 10
    return rows, fps


class SectionCache:
    """A shape's z = 0 section, computed once and moved rigidly while the shape only turns about z and moves in x and
    y (a planar arm's links, an obstacle moving in the plane); computed anew otherwise."""

    def __init__(self, shape):
        self.shape = shape
        self.reference = None  # (p, R, section) of the last computation

    def polygon(self, p, R):
        if self.reference is not None:
            p0, R0, poly0 = self.reference
            turn = R @ R0.T
            if abs(p[2] - p0[2]) <= 1e-12 and abs(turn[2, 2] - 1.0) <= 1e-12:
                return None if poly0 is None else (poly0 - p0[:2]) @ turn[:2, :2].T + p[:2]
        poly = plane_section(self.shape, p, R)
        self.reference = (np.array(p), np.array(R), poly)
        return poly


class PlanarSection:
    """The artist of one shape's section on 2-D axes, updated in place each frame (hidden where the shape misses the
    plane); clouds are a scatter of the cells near the plane."""

    def __init__(self, ax, shape, **style):
        self.shape, self.cache = shape, SectionCache(shape)
        if is_cloud(shape):
            self.artist = ax.scatter([], [], s=2, marker="s", color=style.get("facecolor", "grey"), animated=True)
        else:
            self.artist = matplotlib.patches.Polygon(np.zeros((3, 2)), closed=True, animated=True, **style)
            ax.add_patch(self.artist)

    def update(self, p, R):
        if is_cloud(self.shape):
            centres, edges = cloud_cells(self.shape, p, R)
            near = np.abs(centres[:, 2]) <= 0.5 * edges + self.shape.get("radius", 0.0)
            self.artist.set_offsets(centres[near, :2] if near.any() else np.zeros((0, 2)))
            self.artist.set_visible(bool(near.any()))
            return
        poly = self.cache.polygon(p, R)
        self.artist.set_visible(poly is not None)
        if poly is not None:
            self.artist.set_xy(poly)


def write_animation(path, images, fps, size):
    """The frames (an iterable of h x w x 3 uint8 arrays, size = (w, h)) as an MP4 (ffmpeg on PATH: H.264 from raw
    RGB frames streamed to its stdin) or a GIF (Pillow), as the file name says."""
    if path.endswith(".mp4"):
        w, h = size
        command = [shutil.which("ffmpeg"), "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s",
                   f"{w}x{h}", "-r", str(fps), "-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-vcodec", "libx264",
                   "-pix_fmt", "yuv420p", "-b:v", "1800k", path]
        with tempfile.TemporaryFile() as log:
            with subprocess.Popen(command, stdin=subprocess.PIPE, stderr=log) as ffmpeg:
                try:
                    for image in images:
                        ffmpeg.stdin.write(image.tobytes())
                except BrokenPipeError:
                    pass  # ffmpeg stopped: its exit code and message say why
                finally:
                    ffmpeg.stdin.close()
            if ffmpeg.returncode != 0:
                log.seek(0)
                raise RuntimeError(f"ffmpeg failed (exit code {ffmpeg.returncode}): "
                                   f"{log.read().decode(errors='replace').strip()}")
        return
    from PIL import Image  # Pillow comes with matplotlib

    frames = [Image.fromarray(image) for image in images]
    frames[0].save(path, save_all=True, append_images=frames[1:], duration=int(round(1000 / fps)), loop=0)


def animate_run(run_dir, quiet):
    """The arm, its collision shapes (when there are obstacles), the obstacles where they are, the end-effector
    trail and the desired path, over the run: animation.mp4 or animation.gif in run_dir.

    Fast: what does not move (axes, path, legend, fixed obstacles) is drawn once; each frame restores that background
    and draws only the moving artists (arm, trail, sections or moving obstacles, title) into the canvas, whose pixels
    are the frame (blitting); the frames are then written in one go."""
    data, summary = load(run_dir)
    frames = load_frames(run_dir, summary)
    if frames is None:
        raise SystemExit(f"plot_run.py: --animate: no frames.csv in {run_dir} (runs of redres before it wrote one)")
    name = run_name(summary, run_dir)
    t_f, pts, rots = frames
    duration = float(data["t"][-1])
    rows, fps = animation_rows(t_f, duration)
    planar = summary["robot"]["kind"] == "planar"
    obs = obstacles(summary)
    shapes = bool(obs) and bool(summary["robot"].get("link_shapes"))
    distance_columns = [c for c in data.dtype.names if c.split(".")[-1] == "min_obstacle_distance"]
    t_data = data["t"]

    def min_distance(t):
        if not distance_columns:
            return None
        k = int(np.argmin(np.abs(t_data - t)))
        return min(float(data[c][k]) for c in distance_columns)

    file_name = "animation.mp4" if shutil.which("ffmpeg") else "animation.gif"
    fig = plt.figure(figsize=(6.4, 6.0))
    if planar:
        ax = fig.add_subplot(1, 1, 1)
        ax.plot(data["rd_x"], data["rd_y"], "b-", lw=3, alpha=0.25, label="desired path")
        (trail,) = ax.plot([], [], "r", lw=1.2, label="end-effector trajectory", animated=True)
        (arm,) = ax.plot([], [], "-o", color="k", lw=2, ms=4, label="arm", animated=True, zorder=3)
        all_pts = [pts[:, :, :2].reshape(-1, 2), np.column_stack([data["rd_x"], data["rd_y"]])]
        for o in obs:
            r = bounding_radius(o)
            for t in (0.0, duration):
                p, _ = obstacle_pose(o, t)
                all_pts.append(np.array([p[:2] - r, p[:2] + r]))
        if shapes:
            r = max(bounding_radius(sh) for sh in summary["robot"]["link_shapes"])
            all_pts.append(np.vstack([pts[:, :, :2].reshape(-1, 2) - r, pts[:, :, :2].reshape(-1, 2) + r]))
        both = np.vstack(all_pts)
        lo, hi = both.min(axis=0), both.max(axis=0)
        pad = 0.05 * float((hi - lo).max())
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal")
        # A figure of about the scene's shape (the height fixed), so that little of it is margin.
        ratio = (hi[0] - lo[0] + 2 * pad) / max(hi[1] - lo[1] + 2 * pad, 1e-9)
        fig.set_size_inches(float(np.clip(6.0 * ratio + 1.2, 4.8, 10.0)), 6.4)
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.grid(alpha=0.3)
        if obs:
            ax.plot([], [], "s", color=OBSTACLE_COLOUR, label="obstacles")
        obstacle_sections = [PlanarSection(ax, o, facecolor=OBSTACLE_COLOUR, edgecolor="k", lw=0.6, alpha=0.8)
                             for o in obs]
        link_sections = [PlanarSection(ax, shape, facecolor=CLOSEST_COLOUR, edgecolor=CLOSEST_COLOUR, lw=0.5,
                                       alpha=0.25) for shape in summary["robot"]["link_shapes"]] if shapes else []

        def update(k):
            t = t_f[k]
            for section, o in zip(obstacle_sections, obs):
                section.update(*obstacle_pose(o, t))
            for section, (_, p, R) in zip(link_sections, link_shape_poses(summary, rots[k], pts[k])):
                section.update(p, R)
            arm.set_data(pts[k, :, 0], pts[k, :, 1])
            shown = t_data <= t + 1e-12
            trail.set_data(data["r_x"][shown], data["r_y"][shown])
            return [s.artist for s in obstacle_sections + link_sections if s.artist.get_visible()] + [trail, arm]
    else:
        ax = fig.add_subplot(1, 1, 1, projection="3d")
        ax.plot(data["rd_x"], data["rd_y"], data["rd_z"], "b-", lw=3, alpha=0.25, label="desired path")
        (trail,) = ax.plot([], [], [], "r", lw=1.2, label="end-effector trajectory", animated=True)
        (arm,) = ax.plot([], [], [], "-o", color="k", lw=3, ms=4, label="arm", animated=True)
        equal_3d(ax, np.vstack([scene_points(summary, frames, duration),
                                np.column_stack([data["rd_x"], data["rd_y"], data["rd_z"]])]))
        if obs:
            ax.plot([], [], "s", color=OBSTACLE_COLOUR, label="obstacles")
        for o in obs:
            if not moving(o):
                draw_solid(ax, o, *obstacle_pose(o, 0.0), OBSTACLE_COLOUR, 0.5)
        dynamic = []  # moving obstacles: drawn anew each frame

        def update(k):
            t = t_f[k]
            for artist in dynamic:
                artist.remove()
            dynamic.clear()
            for o in obs:
                if moving(o):
                    dynamic.extend(draw_solid(ax, o, *obstacle_pose(o, t), OBSTACLE_COLOUR, 0.5))
            for artist in dynamic:
                artist.set_animated(True)
                if hasattr(artist, "do_3d_projection"):
                    artist.do_3d_projection()  # what the 3-D axes' draw does for its collections
            arm.set_data_3d(pts[k, :, 0], pts[k, :, 1], pts[k, :, 2])
            shown = t_data <= t + 1e-12
            trail.set_data_3d(data["r_x"][shown], data["r_y"][shown], data["r_z"][shown])
            return dynamic + [trail, arm]

    def set_title(t):
        d = min_distance(t)
        extra = f", smallest obstacle distance {d * 1000:.1f} mm" if d is not None and np.isfinite(d) else ""
        ax.set_title(f"{name}: t = {t:.2f} s{extra}", fontsize=9)

    set_title(t_f[rows[0]])  # before the layout, so that it keeps room for the title
    # The legend below the axes, where the arm never goes.
    handles, labels = ax.get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    fig.set_dpi(90 if planar else 80)
    ax.title.set_animated(True)
    canvas = fig.canvas
    canvas.draw()  # everything that is not animated: the background of every frame
    background = canvas.copy_from_bbox(fig.bbox)
    size = canvas.get_width_height()

    def images():  # the frames, drawn as the writer takes them
        for k in rows:
            canvas.restore_region(background)
            set_title(t_f[k])
            for artist in update(k) + [ax.title]:
                ax.draw_artist(artist)
            yield np.asarray(canvas.buffer_rgba())[..., :3].copy()

    path = os.path.join(run_dir, file_name)
    try:
        save_output(path, lambda target: write_animation(target, images(), fps, size))
    finally:
        plt.close(fig)
    if not quiet:
        print(f"{len(rows)} frames at {fps} frames/s, " + ("an MP4 (ffmpeg)" if file_name.endswith(".mp4") else
                                                           "a GIF (ffmpeg is not on PATH)"))
    return path


# Line styles of the compared runs, the first drawn widest and lowest, so that a curve under another stays visible.
COMPARE_STYLES = [
    dict(ls="-", lw=4.0, alpha=0.45, marker=None),
    dict(ls="--", lw=1.8, alpha=1.0, marker="o"),
    dict(ls="-.", lw=1.6, alpha=1.0, marker="s"),
    dict(ls=":", lw=2.0, alpha=1.0, marker="^"),
    dict(ls=(0, (5, 1, 1, 1, 1, 1)), lw=1.4, alpha=1.0, marker="D"),
]
COINCIDE_FRACTION = 2e-3  # two curves coincide where they differ by less than this fraction of w's range


def zoom_range(t, curves):
    """The time range where the compared curves differ: from the start to a little after the last pair of them
    comes within COINCIDE_FRACTION of w's range and stays there; the whole run when no pair coincides for good (or
    all do from the start). (t_end, the pairs that coincide for good with the time each starts to)."""
    values = np.vstack(curves)
    span = max(float(np.nanmax(values) - np.nanmin(values)), 1e-300)
    joined = []
    for a in range(len(curves)):
        for b in range(a + 1, len(curves)):
            apart = np.abs(curves[a] - curves[b]) > COINCIDE_FRACTION * span
            if not apart.any():
                continue  # the same curve throughout: nothing to zoom on for this pair
            last = int(np.nonzero(apart)[0][-1])
            if last < len(t) - 1 and t[last] < 0.9 * t[-1]:
                joined.append((a, b, float(t[last + 1])))
    if not joined:
        return float(t[-1]), []
    end = float(t[0]) + 1.25 * (max(j[2] for j in joined) - float(t[0]))
    return min(float(t[-1]), nice_ceiling(end)), joined


def nice_ceiling(x):
    """The smallest of 1, 2, 2.5, 5 times a power of ten that is >= x (x > 0): a round end for the zoom."""
    if x <= 0:
        return x
    scale = 10.0 ** np.floor(np.log10(x))
    return next(m * scale for m in (1.0, 2.0, 2.5, 5.0, 10.0) if m * scale >= x * (1 - 1e-12))


def plot_compare(dirs, out, quiet):
    """Fig. 5: w of every run over the whole time (a), and zoomed on the time where the curves differ (b)."""
    runs = []
    for d in dirs:
        data, summary = load(d)
        runs.append((data["t"], data["manipulability"], run_name(summary, d)))
    t_common = runs[0][0]
    same_time = all(len(r[0]) == len(t_common) and np.allclose(r[0], t_common) for r in runs)
    t_end, joined = zoom_range(t_common, [r[1] for r in runs]) if same_time and len(runs) > 1 else (None, [])
    zoom = t_end is not None and t_end < 0.9 * float(t_common[-1])
    fig, axes = plt.subplots(1, 2 if zoom else 1, figsize=(12, 4.8) if zoom else (8, 4.8), squeeze=False)
    panels = axes[0]
    for ax in panels:
        for i, (t, w, label) in enumerate(runs):
            style = COMPARE_STYLES[i % len(COMPARE_STYLES)]
            colour = f"C{i % 10}"
            ax.plot(t, w, color=colour, ls=style["ls"], lw=style["lw"], alpha=style["alpha"], zorder=2 + i,
                    marker=style["marker"], markevery=(i * 0.03 % 0.09, 0.09), ms=5, mfc="white", mec=colour,
                    label=label)
        ax.set_xlabel("t (s)")
        ax.set_ylabel(r"$w = \det(JJ^T)$")
        ax.grid(alpha=0.3)
    panels[0].set_title("(a) the whole run" if zoom else "Manipulability of the compared schemes")
    if zoom:
        ax = panels[1]
        ax.set_xlim(float(t_common[0]), t_end)
        inside = t_common <= t_end
        lo = min(float(np.nanmin(w[inside])) for _, w, _ in runs)
        hi = max(float(np.nanmax(w[inside])) for _, w, _ in runs)
        pad = 0.05 * max(hi - lo, 1e-12)
        ax.set_ylim(lo - pad, hi + pad)
        ax.set_title(f"(b) zoom on t $\\leq$ {t_end:.3g} s, where the schemes differ")
        panels[0].axvspan(float(t_common[0]), t_end, color="0.85", zorder=0, label=None)
        notes = [f"{runs[a][2]} and {runs[b][2]} coincide from t $\\approx$ {at:.2g} s" for a, b, at in joined]
        ax.text(0.98, 0.03, "\n".join(notes), transform=ax.transAxes, ha="right", va="bottom", fontsize=8,
                bbox=dict(boxstyle="round", fc="white", ec="0.7", alpha=0.9))
    fig.suptitle("Manipulability of the compared schemes" if zoom else "")
    bottom = shared_legend(fig, [panels[0]], ncol=min(len(runs), 3), fontsize=10)
    fig.tight_layout(rect=(0, bottom, 1, 1))
    os.makedirs(out, exist_ok=True)
    save_output(os.path.join(out, "fig5_manipulability.png"), lambda target: fig.savefig(target, dpi=110))
    plt.close(fig)
    if not quiet:
        print(f"comparison figure written to {out}")
    for d in dirs:
        plot_run(d, quiet)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run_dir", nargs="?", help="a run directory (trajectory.csv, summary.json)")
    p.add_argument("--animate", action="store_true",
                   help="write RUN_DIR/animation.mp4 (ffmpeg on PATH) or else RUN_DIR/animation.gif, not the figures")
    p.add_argument("--compare", nargs="+", metavar="DIR", help="run directories to compare")
    p.add_argument("--out", help="output directory for the comparison figure")
    p.add_argument("--quiet", action="store_true")
    a = p.parse_args()
    if a.animate:
        if not a.run_dir or a.compare:
            p.error("--animate takes one RUN_DIR")
        animate_run(a.run_dir, a.quiet)
    elif a.compare:
        plot_compare(a.compare, a.out or os.path.dirname(os.path.normpath(a.compare[0])), a.quiet)
    elif a.run_dir:
        plot_run(a.run_dir, a.quiet)
    else:
        p.error("give RUN_DIR or --compare DIR...")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (OutputError, RuntimeError) as e:  # RuntimeError: ffmpeg failed
        print(f"plot_run.py: {e}", file=sys.stderr)
        sys.exit(2)
