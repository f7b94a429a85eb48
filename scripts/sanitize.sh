#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UBSan (docs/reliability.md):
# builds build-asan/ with -DMIMIC2D_SANITIZE=ON (gcc) and runs ctest there,
# shared reference data hidden as in CI. Any sanitizer report fails its
# test (UBSan does not recover). Arguments go to ctest, e.g. -R Checkpoint.
# LeakSanitizer is off: LibTorch and OpenBLAS keep process-lifetime pools.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -f build-asan/build.ninja ]; then
  cmake -S . -B build-asan -G Ninja -DMIMIC2D_SANITIZE=ON \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
fi
cmake --build build-asan -j"$(nproc)"
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
MIMIC2D_SHARED_DATA='' ctest --test-dir build-asan --output-on-failure \
  -j"$(nproc)" --timeout 3000 "$@" 2>&1 | tee build-asan/ctest.log
