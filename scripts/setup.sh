#!/usr/bin/env bash
# Installs every Debian package Plano needs to build, test and benchmark.
# Idempotent: does nothing (and prints nothing) when everything is already installed.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  clang libclang-rt-dev
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  glslang-tools spirv-tools
  libeigen3-dev libopenmesh-dev libglm-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libspectra-dev libsuitesparse-dev libcli11-dev nlohmann-json3-dev
  # CHOLMOD and SPQR run their dense fronts through BLAS/LAPACK: OpenBLAS instead of the
  # reference implementation makes the sparse factorizations 1.4-2.4x faster (README).
  # The serial build, so that it never competes with Plano's own threads.
  libopenblas0-serial
  # The BLAS interface Plano calls itself (cblas.h, libblas.so) for the linear spaces' large
  # dense products; at run time it resolves to the OpenBLAS above.
  libblas-dev
)

missing=()
for pkg in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done

if ((${#missing[@]} == 0)); then
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  SUDO="sudo"
fi

echo "plano setup: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq >/dev/null
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
