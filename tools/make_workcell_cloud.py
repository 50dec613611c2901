#!/usr/bin/env python3
"""Writes the synthetic depth scan of the Panda's work cell that configs/panda_point_cloud.toml avoids:
100,000 points on a table top (z = 0.47 m), a pole standing on it, a bin at its far corner and a wall beside the arm,
each surface sampled uniformly by area with 2 mm of Gaussian sensor noise. Deterministic (numpy's PCG64, seed 2026),
so the file it writes is the one shipped: `tools/make_workcell_cloud.py configs/clouds/panda_workcell.ply`.
"""
import sys

import numpy as np

N = 100_000
NOISE = 0.002


def rect(rng, n, origin, u, v):
    """n points on the rectangle origin + s u + t v, s, t in [0, 1]."""
    s, t = rng.random((2, n))
    return np.asarray(origin) + np.outer(s, u) + np.outer(t, v)


def cylinder(rng, n, base, radius, height):
    a, h = rng.random((2, n))
    a *= 2 * np.pi
    return np.column_stack([base[0] + radius * np.cos(a), base[1] + radius * np.sin(a), base[2] + height * h])


def main(out):
    rng = np.random.default_rng(2026)
    parts = [
        # the table top, 0.6 x 0.8 m, its upper face at z = 0.47
        (0.40, lambda n: rect(rng, n, [0.15, -0.40, 0.47], [0.6, 0, 0], [0, 0.8, 0])),
        # a pole of radius 3 cm on the table, 0.5 m tall
        (0.15, lambda n: cylinder(rng, n, [0.20, -0.13, 0.47], 0.03, 0.50)),
        # a bin (open box, 0.15 x 0.18 x 0.10 m) at the table's far left corner: four walls and a floor
        (0.15, lambda n: np.concatenate([
            rect(rng, n // 5, [0.60, 0.22, 0.47], [0.15, 0, 0], [0, 0, 0.10]),
            rect(rng, n // 5, [0.60, 0.40, 0.47], [0.15, 0, 0], [0, 0, 0.10]),
            rect(rng, n // 5, [0.60, 0.22, 0.47], [0, 0.18, 0], [0, 0, 0.10]),
            rect(rng, n // 5, [0.75, 0.22, 0.47], [0, 0.18, 0], [0, 0, 0.10]),
            rect(rng, n - 4 * (n // 5), [0.60, 0.22, 0.475], [0.15, 0, 0], [0, 0.18, 0])])),
        # a wall on the arm's right, 1 m long and 0.8 m tall, at y = -0.55
        (0.30, lambda n: rect(rng, n, [-0.20, -0.55, 0.47], [1.0, 0, 0], [0, 0, 0.8])),
    ]
    counts = [int(round(f * N)) for f, _ in parts]
    counts[0] += N - sum(counts)
    points = np.concatenate([make(n) for n, (_, make) in zip(counts, parts)])
    points += rng.normal(0.0, NOISE, points.shape)
    assert points.shape == (N, 3)
    with open(out, "xb") as f:  # never overwrites
        f.write(("ply\nformat binary_little_endian 1.0\ncomment redres tools/make_workcell_cloud.py (seed 2026)\n"
                 f"element vertex {N}\nproperty float x\nproperty float y\nproperty float z\nend_header\n").encode())
        f.write(points.astype("<f4").tobytes())


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: make_workcell_cloud.py OUT.ply")
    main(sys.argv[1])
