#!/usr/bin/env bash
# The viewer's screenshots in docs/figures/ (docs/viewer.md): the paper's three schemes overlaid, and the Panda (its
# maker's meshes as convex hulls) past a table and a pole, each taken by headless Chromium from the view.html that
# `redres compare --view` / `redres run --view` writes. Needs the release build and Debian's chromium and
# libjs-three (scripts/install_deps.sh installs both). Writes into a fresh temporary directory, then copies the two
# PNG files into docs/figures/.
set -euo pipefail
cd "$(dirname "$0")/.."
redres=build/release/bin/redres
work=$(mktemp -d)
shoot() {  # shoot PAGE FRAGMENT PNG
  chromium --headless --no-sandbox --disable-dev-shm-usage --enable-unsafe-swiftshader --hide-scrollbars --window-size=1400,850 \
    --user-data-dir="$work/profile" --virtual-time-budget=3000 --screenshot="$3" "file://$1#$2" 2>/dev/null
}
"$redres" compare configs/paper_r_tvcmm.toml configs/paper_r_constant_p.toml configs/paper_r_mvn.toml \
  --out "$work/paper" --no-plots --quiet --view
"$redres" run configs/panda_hulls_table_pole.toml --out "$work/panda" --quiet --view
shoot "$work/paper/view.html" "frame=60" "$work/viewer_paper_r.png"
shoot "$work/panda/view.html" "frame=250" "$work/viewer_panda_table_pole.png"
cp "$work/viewer_paper_r.png" "$work/viewer_panda_table_pole.png" docs/figures/
ls -l "$work"/*/view.html docs/figures/viewer_*.png
echo "viewer_screenshots: the runs and their pages are in $work"
