#!/bin/bash
# Times the walk from 2D to Succ 90 % (issue 13) on an otherwise idle
# machine: trains CONFIG from a fresh start for MINUTES of wall time,
# keeping every checkpoint (`train --keep-checkpoints`: ckpt_<samples>.pt),
# then evaluates each as eval_curve.sh does and prints the first
# checkpoint at Succ >= 0.9 with its samples and training wall time.
#   docs/experiments/walk2d_fast/timed_run.sh configs/walk2d_fast.yaml 40 floor6e-5_timed
# Needs runs/walk_fitted.json (the config's header) and build/mimic2d. The
# run folder is the config's run.run_dir and must not exist yet.
set -euo pipefail
cd "$(dirname "$0")/../../.."
[ $# -eq 3 ] || { echo "usage: $0 CONFIG MINUTES VARIANT" >&2; exit 2; }
config=$1 minutes=$2 variant=$3
dir=$(sed -n 's/^  run_dir: *\([^ #]*\).*/\1/p' "$config")
[ -n "$dir" ] || { echo "timed_run: no run.run_dir in $config" >&2; exit 1; }
[ ! -e "$dir" ] || { echo "timed_run: $dir exists; a timed run starts fresh" >&2; exit 1; }
cp build/mimic2d /tmp/timed_run_mimic2d  # rebuilding must not touch the run
# A checkpoint every minute (the curve's resolution; learning is the same).
sed 's/^  checkpoint_minutes: .*/  checkpoint_minutes: 1/' "$config" \
  > /tmp/timed_run_config.yaml
timeout -s INT "${minutes}m" /tmp/timed_run_mimic2d train \
  /tmp/timed_run_config.yaml --keep-checkpoints > "$dir.log" 2>&1 || true
MIMIC2D=/tmp/timed_run_mimic2d docs/experiments/walk2d_fast/eval_curve.sh "$dir" "$variant" | tee "$dir/eval_curve.csv"
awk -F, '$4 >= 0.9 { printf "first Succ >= 0.9: %s samples, %.1f min of training\n", $2, $3 / 60; found = 1; exit }
         END { if (!found) print "Succ 0.9 not reached" }' "$dir/eval_curve.csv"
