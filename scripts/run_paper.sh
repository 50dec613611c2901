#!/usr/bin/env bash
# The main job: installs what is missing, builds the release configuration, and reproduces the paper's
# comparison: TVCMM (p = 2 sin(pi t / T)), constant p = 1 and MVN (p = 0) writing the letter R in T = 40 s.
# Writes out/paper/comparison.md, the per-scheme trajectories and summaries, the figures (Figs. 3-7, 9(b)) and
# view.html, the three runs replayed in 3-D in a browser (docs/viewer.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
# Only what the comparison runs: the CLI and the library (the tests, benchmarks, examples and the Python module are
# scripts/test.sh's).
bash scripts/build.sh release redres_cli
# The figures run plot_run.py with the python3 found on PATH; put Debian's, which has the matplotlib and numpy that
# install_deps.sh installed, first (another python3, e.g. a pyenv shim, may come first and lack them).
export PATH="/usr/bin:$PATH"
./build/release/bin/redres compare configs/paper_r_tvcmm.toml configs/paper_r_constant_p.toml \
  configs/paper_r_mvn.toml --out out/paper --view "$@"
