#!/usr/bin/env bash
# Builds the whole test suite with AddressSanitizer + UndefinedBehaviorSanitizer and runs it
# (Vulkan tests included, on lavapipe). Any sanitizer report fails the run.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
BUILD_DIR=${PLANO_SANITIZE_BUILD_DIR:-build-sanitize}
# clang, -O1 with line tables only: a quicker build than GCC's or -O2 -g (this build is CI's
# longest step), with stack traces that still name file and line; the Release stage is built
# by GCC, so the suite is compiled by both. No NDEBUG: Eigen's and nlohmann-json's assertions
# are checked as well.
cmake -S . -B "$BUILD_DIR" -DCMAKE_CXX_COMPILER="${PLANO_SANITIZE_CXX:-clang++}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DPLANO_SANITIZE=ON -DPLANO_BUILD_BENCHMARKS=OFF \
  -DPLANO_UNITY_BUILD="${PLANO_UNITY_BUILD:-ON}" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target plano plano_tests plano_quickstart
export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}
# LeakSanitizer is off: the Vulkan loader and lavapipe keep process-lifetime allocations.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)"
