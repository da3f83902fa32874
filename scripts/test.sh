#!/usr/bin/env bash
# Installs dependencies, builds Plano and runs everything CI checks, in three stages:
#   1. Release build, the whole test suite (CPU and Vulkan on lavapipe, validation layers on);
#   2. the same suite built with AddressSanitizer + UndefinedBehaviorSanitizer (scripts/sanitize.sh);
#   3. a fuzz smoke run of every reader and the constraint parser (scripts/fuzz.sh).
# This is exactly what CI runs. PLANO_TEST_STAGES (default "release sanitize fuzz") picks
# stages for a quicker local loop; PLANO_FUZZ_SECONDS (default 30) bounds each fuzz target;
# PLANO_UNITY_BUILD=OFF compiles every source on its own (as a default development build).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
stages=" ${PLANO_TEST_STAGES:-release sanitize fuzz} "
# Without a GPU, the Vulkan tests run on Mesa's lavapipe.
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}

# Each step's wall time, printed at the end: what a slower CI run spent its time on.
timings=""
timed() {
  local label="$1" start=$SECONDS
  shift
  "$@"
  timings+="$label: $((SECONDS - start)) s"$'\n'
}

if [[ "$stages" == *" release "* ]]; then
  echo "== stage 1/3: release build and tests" >&2
  BUILD_DIR=${PLANO_BUILD_DIR:-build}
  # Sources compiled in batches (PLANO_UNITY_BUILD): 535 s instead of 731 s on 2 cores.
  cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release -DPLANO_UNITY_BUILD="${PLANO_UNITY_BUILD:-ON}" >/dev/null
  timed "release build" cmake --build "$BUILD_DIR" -j"$(nproc)"
  timed "release tests" ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)"
  # The installed package as another project sees it: examples/ built on its own against
  # `cmake --install` (find_package(Plano), Plano::plano), and its program run.
  installed_package_check() {
    local prefix consumer
    prefix=$(realpath -m "$BUILD_DIR/installed-package")
    consumer=$(realpath -m "$BUILD_DIR/installed-package-examples")
    rm -rf "$prefix" "$consumer"
    cmake --install "$BUILD_DIR" --prefix "$prefix" >/dev/null
    cmake -S examples -B "$consumer" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
    cmake --build "$consumer" -j"$(nproc)" >/dev/null
    "$consumer/plano_quickstart" "$consumer/quickstart.obj"
  }
  timed "installed package" installed_package_check
fi
if [[ "$stages" == *" sanitize "* ]]; then
  echo "== stage 2/3: AddressSanitizer + UndefinedBehaviorSanitizer build and tests" >&2
  timed "sanitizer build and tests" bash scripts/sanitize.sh
fi
if [[ "$stages" == *" fuzz "* ]]; then
  echo "== stage 3/3: fuzz smoke run" >&2
  timed "fuzz build and run" bash scripts/fuzz.sh "${PLANO_FUZZ_SECONDS:-30}"
fi
printf "== wall time per step\n%s" "$timings" >&2
