#!/usr/bin/env bash
# The main job: installs what is missing, builds the release configuration, and runs the paper's case.
# Until the scenario runner exists, it prints the paper's push-rod arm at theta(0).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install_deps.sh
bash scripts/build.sh release
./build/release/bin/redres robot robots/paper_pushrod_6dof.toml
