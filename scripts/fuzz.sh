#!/usr/bin/env bash
# Fuzzes every reader of user input with libFuzzer + ASan + UBSan
# (docs/reliability.md). Builds build-fuzz/ with clang, then runs each
# target for RUNS executions (default 1000000) from a copy of its seed
# corpus in fuzz/corpus/, and prints one line per target. A crash stops
# that target and leaves its input in build-fuzz/artifacts/<target>/.
#   scripts/fuzz.sh [TARGET...]     e.g. scripts/fuzz.sh bundle bvh
# Environment: RUNS, JOBS (parallel targets, default 2), MAX_LEN (bytes,
# default: the target's largest seed, at least 4096).
set -uo pipefail
cd "$(dirname "$0")/.." || exit 1
runs=${RUNS:-1000000}
jobs=${JOBS:-2}
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(clip_json openpose bundle deepmimic bvh config checkpoint)
fi

if [ ! -f build-fuzz/build.ninja ]; then
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja \
    -DMIMIC2D_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null || exit 1
fi
cmake --build build-fuzz --target fuzz_targets -j2 || exit 1

run_target() {
  local name=$1
  local corpus=build-fuzz/corpus/$name artifacts=build-fuzz/artifacts/$name
  mkdir -p "$corpus" "$artifacts"
  cp -n fuzz/corpus/"$name"/* "$corpus"/
  local largest
  largest=$(find fuzz/corpus/"$name" -type f -printf '%s\n' | sort -n | tail -1)
  local max_len=${MAX_LEN:-$(( largest > 4096 ? largest : 4096 ))}
  local log=build-fuzz/$name.log start=$SECONDS
  UBSAN_OPTIONS=print_stacktrace=1 ASAN_OPTIONS=detect_leaks=0 \
    build-fuzz/"${name}"_fuzzer "$corpus" -runs="$runs" -max_len="$max_len" \
    -rss_limit_mb=2048 -timeout=20 -print_final_stats=1 \
    -artifact_prefix="$artifacts"/ > "$log" 2>&1
  local status=$?
  local execs
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$')
  local crashes
  crashes=$(find "$artifacts" -type f | wc -l)
  printf '%-10s exit %d  executions %s  seconds %d  corpus %d  crash files %d\n' \
    "$name" "$status" "${execs:-?}" $((SECONDS - start)) \
    "$(find "$corpus" -type f | wc -l)" "$crashes"
  return $status
}

failed=0
pids=()
for name in "${targets[@]}"; do
  run_target "$name" &
  pids+=($!)
  if [ ${#pids[@]} -ge "$jobs" ]; then
    wait "${pids[0]}" || failed=1
    pids=("${pids[@]:1}")
  fi
done
for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
exit $failed
