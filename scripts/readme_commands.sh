#!/usr/bin/env bash
# Runs every command line of README.md's ```sh blocks, in order, as a
# newcomer would paste them (test.sh runs this; ./setup.sh and ./test.sh
# themselves excepted). They run in a scratch folder that links build/,
# assets/ and configs/, so their runs/ outputs land there and later
# commands read what earlier ones wrote.
# Every command must exit 0, except the open-ended ones, which are stopped:
#  - `mimic2d train ...` gets Ctrl-C (SIGINT) after TRAIN_S seconds and must
#    checkpoint and stop, as the README says (exit 130, "interrupted");
#  - `mimic2d bench fit` without --quick (many minutes) gets SIGINT after
#    BENCH_FIT_S seconds and must have printed no error by then.
set -uo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
train_s=${TRAIN_S:-25}
bench_fit_s=${BENCH_FIT_S:-30}
limit_s=${LIMIT_S:-900}
sandbox=$(mktemp -d)
trap 'rm -rf "$sandbox"' EXIT
for linked in build assets configs bench; do ln -s "$repo/$linked" "$sandbox/$linked"; done

# The README's command lines, continuation lines joined, comments dropped.
mapfile -t commands < <(awk '
  /^```sh$/ { inside = 1; next }
  /^```$/   { inside = 0; next }
  inside {
    line = $0
    sub(/[ \t]+#.*$/, "", line)
    if (line ~ /\\$/) { sub(/\\$/, "", line); pending = pending line; next }
    print pending line; pending = ""
  }' "$repo/README.md")

failed=0
count=0
cd "$sandbox" || exit 1
for command in "${commands[@]}"; do
  case "$command" in ./setup.sh*|./test.sh*|"") continue ;; esac
  count=$((count + 1))
  log=$(mktemp)
  start=$SECONDS
  if [[ "$command" == build/mimic2d\ train* ]]; then
    timeout --preserve-status -s INT "$train_s" bash -c "$command" > "$log" 2>&1
    status=$?
    if { [ $status -eq 130 ] || [ $status -eq 0 ]; } && grep -q "checkpoint" "$log"; then
      verdict="ok (Ctrl-C after ${train_s} s)"
    else
      verdict="FAILED (exit $status after Ctrl-C)"
    fi
  elif [[ "$command" == build/mimic2d\ bench\ fit* && "$command" != *--quick* ]]; then
    timeout --preserve-status -s INT "$bench_fit_s" bash -c "$command" > "$log" 2>&1
    status=$?
    if grep -qi "error" "$log" || { [ $status -ne 0 ] && [ $status -ne 130 ]; }; then
      verdict="FAILED (exit $status)"
    else
      verdict="ok (stopped after ${bench_fit_s} s)"
    fi
  else
    timeout "$limit_s" bash -c "$command" > "$log" 2>&1
    status=$?
    verdict=$([ $status -eq 0 ] && echo ok || echo "FAILED (exit $status)")
  fi
  printf '%-4s %4d s  %s\n' "${verdict%% *}" $((SECONDS - start)) "$command"
  if [[ "$verdict" == FAILED* ]]; then
    failed=1
    echo "     $verdict; last lines:"
    tail -n 15 "$log" | sed 's/^/     | /'
  fi
  rm -f "$log"
done
echo "== README commands: $count run, $([ $failed -eq 0 ] && echo 'all ok' || echo 'some FAILED')"
exit $failed
