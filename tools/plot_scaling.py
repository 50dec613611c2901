#!/usr/bin/env python3
"""Plots BM_Scaling (redres-bench --benchmark_filter=Scaling --benchmark_out=FILE --benchmark_out_format=json):
time per control step against the number of joints, per engine, planar and spatial chains, on log-log axes.

    plot_scaling.py BENCH.json OUT.png
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter, NullFormatter  # noqa: E402

if len(sys.argv) != 3:
    sys.exit(__doc__)
with open(sys.argv[1]) as f:
    runs = [b for b in json.load(f)["benchmarks"] if b["name"].startswith("BM_Scaling/")]
# With --benchmark_repetitions, plot the medians; otherwise the single runs.
if any(b.get("aggregate_name") for b in runs):
    runs = [b for b in runs if b.get("aggregate_name") == "median"]
series = {}
for b in runs:
    _, case, n = b["run_name"].split("/")[:3]
    engine, kind = case.rsplit("_", 1)
    series.setdefault((kind, engine), []).append((int(n), b["per_step"] * 1e6))
fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
for ax, kind in zip(axes, ("planar", "spatial")):
    for (k, engine), points in sorted(series.items()):
        if k != kind:
            continue
        points.sort()
        ax.loglog([p[0] for p in points], [p[1] for p in points], "o-", label=engine)
    ax.set_title(f"{kind} chains")
    ax.set_xlabel("joints n")
    ax.grid(alpha=0.3, which="both")
    # The joint counts as plain numbers at the measured n (not 2 x 10^1).
    ns = sorted({p[0] for (k, _), points in series.items() if k == kind for p in points})
    if ns:
        ax.set_xticks(ns)
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())
axes[0].set_ylabel("time per step (us)")
# One legend for both panels, below them (it covered measured points in a corner).
handles = {}
for ax in axes:
    for h, label in zip(*ax.get_legend_handles_labels()):
        handles.setdefault(label, h)
legend = fig.legend(list(handles.values()), list(handles.keys()), loc="lower center", ncol=max(len(handles), 1),
                    frameon=False)
fig.canvas.draw()
fig.tight_layout(rect=(0, legend.get_window_extent().height / fig.bbox.height + 0.01, 1, 1))
fig.savefig(sys.argv[2], dpi=120)
print(f"written: {sys.argv[2]}")
