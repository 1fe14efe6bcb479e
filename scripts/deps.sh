#!/usr/bin/env bash
# Installs the Debian packages gssm needs, only those missing. Sourced by
# scripts/demo and scripts/test. Uses sudo when not root.
set -euo pipefail

GSSM_PACKAGES=(
  cmake g++ make pkg-config
  libeigen3-dev libsuitesparse-dev
  libgtest-dev libbenchmark-dev
  libmrpt-math-dev libmrpt-random-dev libmrpt-system-dev libmrpt-config-dev
  libmrpt-img-dev libmrpt-opengl-dev
  libegl-mesa0 libgl1-mesa-dri
  python3
  pybind11-dev python3-dev python3-numpy python3-pytest python3-distributed python3-matplotlib
  python3-venv python3-pip python3-setuptools python3-wheel
  clang libclang-rt-14-dev
  locales
  doxygen python3-sphinx python3-breathe python3-sphinx-rtd-theme python3-myst-parser
)

gssm_install_deps() {
  local missing=()
  for p in "${GSSM_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  echo "gssm: installing missing packages: ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}
