#!/usr/bin/env bash
# Packs the CPU-vs-Vulkan benchmarks to run on another machine that has a GPU and its
# Vulkan driver but not Plano's build dependencies (a cluster's GPU node, a cloud GPU
# without network access): the Release `plano_bench` and `plano`, the shared libraries
# they load beside the C library (SuiteSparse, OpenBLAS, Google Benchmark, the C++ and
# Fortran runtimes, the Vulkan loader) and `run.sh`, which runs them from there.
#
#   bash scripts/bench-bundle.sh [DIR]          # default DIR: build/bench-bundle (~25 MiB)
#   DIR/run.sh [FILTER] [plano_bench options]   # on the GPU machine (FILTER '': the default runs)
#
# run.sh writes Google Benchmark's JSON (with the Vulkan device's name in its context) to
# DIR/results/ and prints the console table. Without FILTER it measures the kernel and
# whole-iteration benchmarks of README.md's tables, ~4k to 1M faces, in three runs, each
# with its own JSON file, in the order that matters on a GPU whose time is short: the
# Vulkan kernels (bench-<date>-kernels.json), the Vulkan whole iterations (-loops.json: the
# global step and the deformation iteration up to 1M faces) and then their CPU
# counterparts (-cpu.json); a run cut short keeps the files of the runs before it. With
# FILTER, one run (bench-<date>.json). run.sh refuses to measure on a CPU device (lavapipe) unless
# PLANO_BENCH_ALLOW_CPU_DEVICE=1: the bundle's purpose is the GPU's figures.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${PLANO_BUILD_DIR:-build}
out=${1:-$BUILD_DIR/bench-bundle}
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)" --target plano plano_bench
rm -rf "$out"
mkdir -p "$out/bin" "$out/lib"
cp "$BUILD_DIR/bench/plano_bench" "$BUILD_DIR/plano" "$out/bin/"
# Every library the two programs load, but the C library's own (libc, libm, the dynamic
# loader), which must be the target machine's.
libraries=$(ldd "$out/bin/plano_bench" "$out/bin/plano")
if grep -q "not found" <<<"$libraries"; then
  echo "bench-bundle: libraries the programs need are missing here:" >&2
  grep "not found" <<<"$libraries" >&2
  exit 1
fi
awk '$2 == "=>" && $3 ~ /^\// {print $3}' <<<"$libraries" | sort -u |
  grep -v -E '/(libc|libm|libdl|libpthread|librt|ld-linux[^/]*)\.so' | while read -r library; do
  cp -L "$library" "$out/lib/"
done
cat > "$out/run.sh" <<'RUN'
#!/usr/bin/env bash
# Runs the bundled benchmarks (see scripts/bench-bundle.sh in Plano's sources).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
filter=${1:-}
shift || true
kernels='FacePlanarity|ProjectiveFits|ClosestRotations|IdealMaps|Spmv|SpdSolve|MultigridCycle|BM_LocalStep|RigidLocalStep'
loops='BM_GlobalStep|DeformationIteration|PqSubdivisionLevel'  # also SubspaceDeformationIteration/<space>
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# The Vulkan device the benchmarks will use, as `plano` names its backend.
mkdir -p "$here/results"
stamp=$(date +%Y-%m-%dT%H%M%S)
probe="$here/results/.probe-$stamp.obj"
"$here/bin/plano" -q generate cube -o "$probe"
if ! report=$("$here/bin/plano" --backend vulkan info "$probe" --json); then
  rm -f "$probe"
  echo "run.sh: no usable Vulkan device (the error above); the benchmarks would measure the CPU only" >&2
  exit 2
fi
rm -f "$probe"
device=$(grep '"backend"' <<<"$report" | sed 's/.*"backend": "\(.*\)",*/\1/')
echo "run.sh: $device"
if grep -q -i 'llvmpipe\|lavapipe' <<<"$device" && [[ "${PLANO_BENCH_ALLOW_CPU_DEVICE:-0}" != 1 ]]; then
  echo "run.sh: the Vulkan device is Mesa's CPU emulation, not a GPU; set PLANO_BENCH_ALLOW_CPU_DEVICE=1 to measure it anyway" >&2
  exit 2
fi
echo "$device" > "$here/results/bench-$stamp.device.txt"
measure() {  # measure FILTER JSON [plano_bench options]
  local result="$here/results/$2"
  "$here/bin/plano_bench" --benchmark_filter="$1" --benchmark_out="$result" --benchmark_out_format=json "${@:3}"
  echo "run.sh: results in $result (device: $device)"
}
if [[ -n "$filter" ]]; then
  measure "$filter" "bench-$stamp.json" "$@"
else
  measure "($kernels)/vulkan" "bench-$stamp-kernels.json" "$@"
  measure "($loops)(/[a-z]+)?/vulkan" "bench-$stamp-loops.json" "$@"
  measure "($kernels|$loops)(/[a-z]+)?/cpu" "bench-$stamp-cpu.json" "$@"
fi
RUN
chmod +x "$out/run.sh"
echo "bench-bundle: $(du -sh "$out" | cut -f1) in $out; run $out/run.sh on the target machine"
