#!/usr/bin/env python3
"""Plots each task's error over time for one or more runs of schemes with tasks (docs/tasks.md): one panel per task
(its `<name>_error` column, and `<name>_orientation_error` where it has one), one line per run, labelled with the
run's `label`. The runs of one scenario in each priority order show which task gives way.

    plot_tasks.py OUT.png RUN_DIR [RUN_DIR ...]
"""
import csv
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from redres_output import OutputError, save_output  # noqa: E402


def read_run(directory):
    with open(os.path.join(directory, "summary.json")) as f:
        summary = json.load(f)
    with open(os.path.join(directory, "trajectory.csv")) as f:
        rows = list(csv.reader(f))
    header, data = rows[0], rows[1:]
    columns = {name: [float(r[i]) for r in data] for i, name in enumerate(header)}
    label = summary.get("label") or summary.get("name") or os.path.basename(directory.rstrip("/"))
    return label, columns


def main(argv):
    if len(argv) < 3:
        sys.exit(__doc__)
    out, dirs = argv[1], argv[2:]
    runs = [read_run(d) for d in dirs]
    # The tasks' error columns, in the order the first run that has them lists them.
    panels = []
    for _, columns in runs:
        for name in columns:
            if name.endswith("_error") and name not in ("orientation_error",) and not name.startswith("task_") \
                    and name not in panels and name != "position_error":
                panels.append(name)
    if not panels:
        sys.exit("plot_tasks.py: no task error columns (<task>_error) in " + ", ".join(dirs))
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 2.4 * len(panels) + 0.8), sharex=True, squeeze=False)
    styles = ["-", "--", ":", "-."]
    for ax, name in zip(axes[:, 0], panels):
        for k, (label, columns) in enumerate(runs):
            if name in columns:
                ax.plot(columns["t"], columns[name], styles[k % len(styles)], lw=2.2 - 0.5 * (k % 3), label=label)
        unit = "rad" if name.endswith("orientation_error") else "m"
        ax.set_ylabel(f"{name} ({unit})")
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel("t (s)")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 3), frameon=False)
    fig.suptitle("each task's error over time, per priority order")
    fig.tight_layout(rect=(0, 0.06, 1, 0.97))
    try:
        save_output(out, lambda path: fig.savefig(path, dpi=120))
    except OutputError as e:
        sys.exit(f"plot_tasks.py: {e}")
    print(out)


if __name__ == "__main__":
    main(sys.argv)
