"""Fig. 5 of the paper from Python: w = det(J J') over the R for TVCMM, constant p = 1 and MVN (p = 0).
Usage: python3 fig5_manipulability.py [OUT.png]"""
import pathlib
import sys

import matplotlib.pyplot as plt

import redres

configs = pathlib.Path(__file__).resolve().parents[2] / "configs"
cmp = redres.compare([configs / f"paper_r_{name}.toml" for name in ("tvcmm", "constant_p", "mvn")])
# Each run's label (the configs' `label`) names it; TVCMM is drawn widest, under the others, as p = 1 lies on it
# after t of about 8 s.
for result, style, width in zip(cmp.results, ["-", "--", "-."], [4, 1.5, 1.5]):
    plt.plot(result["t"], result["manipulability"], style, lw=width, label=result.summary["label"])
plt.xlabel("t (s)"), plt.ylabel("w = det(J J')"), plt.legend(), plt.grid(alpha=0.3)
plt.savefig(sys.argv[1] if len(sys.argv) > 1 else "fig5_manipulability.png", dpi=120)
print(cmp.markdown())
