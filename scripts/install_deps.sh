#!/usr/bin/env bash
# Installs the Debian packages redres needs. Idempotent: installs only what is missing and runs
# `apt-get update` only when something must be installed. Extra package names as arguments are installed too
# (scripts/fuzz.sh passes clang's).
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libfcl-dev libccd-dev liboctomap-dev libnlopt-cxx-dev libnlopt-dev libtomlplusplus-dev
  libmuparser-dev libcli11-dev nlohmann-json3-dev liburdfdom-dev libtinyxml-dev libhdf5-dev libassimp-dev libqhull-dev
  libmujoco-dev libegl-dev libegl1 libegl-mesa0 libgl1-mesa-dri libpng-dev libgif-dev
  libjs-three chromium
  libgtest-dev libgmock-dev librapidcheck-dev libbenchmark-dev liborocos-kdl-dev
  python3 python3-dev python3-matplotlib python3-numpy python3-pil python3-h5py python3-cvxopt
  pybind11-dev python3-pybind11 python3-pytest python3-pip python3-setuptools python3-wheel python3-venv mypy
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
