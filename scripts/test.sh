#!/usr/bin/env bash
# Installs dependencies, builds Plano and runs the whole test suite (CPU and Vulkan on
# lavapipe, validation layers on). This is exactly what CI runs.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
BUILD_DIR=${PLANO_BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
# Without a GPU, the Vulkan tests run on Mesa's lavapipe.
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)"
