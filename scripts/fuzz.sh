#!/usr/bin/env bash
# Build the libFuzzer targets (clang, ASan + UBSan) and run each for SECONDS seconds
# (default 60), seeded from tests/data (and fuzz/seeds; inputs cut to 8 KiB, the very long
# lines are covered by the corpus tests). Fails on any crash, sanitizer
# report, leak, timeout or out-of-memory; prints the executions of each target.
#   scripts/fuzz.sh [SECONDS]
# Environment: PLANO_FUZZ_BUILD_DIR (default build-fuzz), JOBS (default 2).
set -euo pipefail
seconds="${1:-60}"
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${PLANO_FUZZ_BUILD_DIR:-$root/build-fuzz}"

cmake -S "$root" -B "$build" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPLANO_BUILD_FUZZERS=ON -DPLANO_BUILD_TESTS=OFF -DPLANO_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j"${JOBS:-2}" --target fuzz_obj fuzz_off fuzz_ply fuzz_constraints

# Runs one target; its log and execution count land in the build folder.
fuzz_one() {
  local target="$1"
  local corpus="$build/corpus/$target" seeds="$build/seeds/$target" log="$build/fuzz_$target.log"
  mkdir -p "$corpus" "$seeds"
  if [[ "$target" == constraints ]]; then
    cp "$root"/fuzz/seeds/constraints/*.json "$seeds"/
  else
    # Seed with every test file; the readers must cope with any format's bytes.
    find "$root/tests/data" -type f -name "*.$target" -exec cp {} "$seeds"/ \;
  fi
  "$build/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
    -print_final_stats=1 -artifact_prefix="$build/crash-$target-" "$corpus" "$seeds" >"$log" 2>&1
}

# As many targets at once as there are jobs (each fuzzer uses one core), so that the stage
# takes SECONDS per round of JOBS targets rather than per target.
targets=(obj off ply constraints)
jobs="${JOBS:-2}"
declare -A pid
status=0
summary=""
for ((i = 0; i < ${#targets[@]}; i += jobs)); do
  for target in "${targets[@]:i:jobs}"; do
    echo "== fuzz_$target for ${seconds}s"
    fuzz_one "$target" &
    pid[$target]=$!
  done
  for target in "${targets[@]:i:jobs}"; do
    log="$build/fuzz_$target.log"
    if ! wait "${pid[$target]}"; then
      echo "fuzz_$target FAILED (see $log):"
      tail -n 40 "$log"
      status=1
    fi
    runs="$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')"
    summary+="fuzz_$target: $runs executions"$'\n'
  done
done
echo "$summary"
exit "$status"
