#!/usr/bin/env bash
# Runs every test: builds if needed, runs the GoogleTest suites through ctest
# (no test may skip: a fresh clone carries everything they need), then a
# quick smoke pass of the benchmarks, then every command line of README.md.
set -euo pipefail
cd "$(dirname "$0")"
[ -d build ] || ./setup.sh --no-demo
cmake --build build -j"$(nproc)"
ctest --test-dir build --output-on-failure -j"$(nproc)" 2>&1 | tee build/ctest.log
skipped=$(grep -c "(Skipped)" build/ctest.log || true)
echo "== skipped tests: ${skipped}"
if [ "${skipped}" -ne 0 ]; then
  echo "error: ${skipped} test(s) skipped; every test must run (see above)"
  exit 1
fi
if [ -x build/m2d_bench ]; then
  echo "== benchmark smoke pass"
  build/m2d_bench --benchmark_min_time=0.01 > build/bench_smoke.txt 2>&1 \
    || { cat build/bench_smoke.txt; exit 1; }
  tail -n 5 build/bench_smoke.txt
fi
# Every command line of the README, as a newcomer pastes them (docs/reliability.md).
echo "== README commands"
scripts/readme_commands.sh
