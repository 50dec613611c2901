#!/usr/bin/env python3
"""Heat map of a redres sweep: one summary figure over two of the sweep's axes, with the variations that did not
run through (any status but ok: failed_steps, task_error_exceeded or error) marked.

    plot_sweep.py SWEEP_DIR [--x KEY] [--y KEY] [--value COLUMN] [--out FILE]

SWEEP_DIR holds sweep.csv (`redres sweep ... --out SWEEP_DIR`, or `redres sweep --merge ...`). --x and --y are two
axis keys of the sweep (default: its first two axis columns, those between `index` and `status`); --value is any
numeric column (default: manipulability.final, w = det(J J') at T). Where several variations share an (x, y) cell
(further axes, or theta0 samples), the cell shows their mean over the variations that ran through, and is marked
only when none did. Writes SWEEP_DIR/sweep_heatmap.png (or --out). Uses matplotlib and numpy; exit code 3 when they
cannot be imported, 2 for a bad argument or file.
"""
import argparse
import csv
import json
import os
import sys
import textwrap

from redres_output import OutputError, save_output  # noqa: E402  (beside this script)

EXIT_MISSING_LIBRARY = 3
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402
    import numpy as np  # noqa: E402
except ImportError as e:
    print(f"plot_sweep.py: {e.name} is not installed for {sys.executable}: apt-get install python3-matplotlib "
          "python3-numpy", file=sys.stderr)
    sys.exit(EXIT_MISSING_LIBRARY)


def fail(message):
    print(f"plot_sweep.py: {message}", file=sys.stderr)
    sys.exit(2)


def axis_values(rows, key):
    """The distinct values of an axis, numerically sorted when they are numbers."""
    values = list(dict.fromkeys(r[key] for r in rows))
    try:
        return sorted(values, key=float)
    except ValueError:
        return values


def tick_labels(values):
    """Axis values as tick labels: numbers with 3 significant digits (more where 3 would make two alike), other
    values as they are."""
    try:
        numbers = [float(v) for v in values]
    except ValueError:
        return list(values)
    for digits in range(3, 18):
        labels = [f"{v:.{digits}g}" for v in numbers]
        if len(set(labels)) == len(set(numbers)):
            return labels
    return list(values)


def wrapped(text, width_inches, fontsize):
    """text broken into lines that fit width_inches at fontsize (an average glyph is about 0.55 em wide)."""
    return "\n".join(textwrap.wrap(text, max(20, int(width_inches * 72 / (0.55 * fontsize)))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sweep_dir")
    parser.add_argument("--x")
    parser.add_argument("--y")
    parser.add_argument("--value", default="manipulability.final")
    parser.add_argument("--out")
    args = parser.parse_args()
    path = os.path.join(args.sweep_dir, "sweep.csv")
    if not os.path.isfile(path):
        fail(f"no sweep.csv in {args.sweep_dir}")
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        rows = list(reader)
        columns = reader.fieldnames or []
    if not rows:
        fail(f"{path} has no rows")
    axes = columns[columns.index("index") + 1:columns.index("status")]
    x = args.x or (axes[0] if axes else None)
    y = args.y or (axes[1] if len(axes) > 1 else None)
    for key, what in ((x, "--x"), (y, "--y")):
        if key is None or key not in columns:
            fail(f"{what} {key!r} is not a column of {path}; the sweep's axes are {axes}")
    if args.value not in columns:
        fail(f"--value {args.value!r} is not a column of {path}")
    xs, ys = axis_values(rows, x), axis_values(rows, y)
    value = np.full((len(ys), len(xs)), np.nan)
    ran = np.zeros((len(ys), len(xs)), dtype=int)
    total = np.zeros((len(ys), len(xs)), dtype=int)
    sums = np.zeros((len(ys), len(xs)))
    for r in rows:
        i, j = ys.index(r[y]), xs.index(r[x])
        total[i, j] += 1
        if r["status"] == "ok" and r[args.value] != "":
            ran[i, j] += 1
            sums[i, j] += float(r[args.value])
    value[ran > 0] = sums[ran > 0] / ran[ran > 0]

    width = max(6.0, 0.28 * len(xs) + 2.5)
    fig, ax = plt.subplots(figsize=(width, max(3.0, 0.45 * len(ys) + 1.5)), constrained_layout=True)
    image = ax.imshow(np.ma.masked_invalid(value), origin="lower", aspect="auto", cmap="viridis")
    fig.colorbar(image, ax=ax, label=args.value)
    bad_i, bad_j = np.nonzero((ran == 0) & (total > 0))
    ax.scatter(bad_j, bad_i, marker="x", color="crimson", s=36)
    ax.set_xticks(range(len(xs)), tick_labels(xs), rotation=90 if len(xs) > 12 else 0,
                  fontsize=7 if len(xs) > 12 else 9)
    ax.set_yticks(range(len(ys)), tick_labels(ys), fontsize=7 if len(ys) > 20 else 9)
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    failed = sum(1 for r in rows if r["status"] != "ok")
    name = os.path.basename(os.path.normpath(args.sweep_dir))
    meta = os.path.join(args.sweep_dir, "sweep.json")
    if os.path.isfile(meta):
        with open(meta) as f:
            name = json.load(f).get("name", name)
    # The title wrapped to the figure's width (a long sweep name would be cut otherwise); it also says what the
    # crosses mean (a legend would cover cells or leave a gap).
    marks = ", marked x (failed steps or error)" if len(bad_i) else ""
    fig.suptitle(wrapped(f"{name}: {args.value}", width, 10) + "\n" +
                 wrapped(f"{len(rows)} variations, {failed} did not run through{marks}", width, 9), fontsize=10)
    out = args.out or os.path.join(args.sweep_dir, "sweep_heatmap.png")
    try:
        save_output(out, lambda target: fig.savefig(target, dpi=120))
    except OutputError as e:
        fail(str(e))
    print(f"written: {out}")


if __name__ == "__main__":
    main()
