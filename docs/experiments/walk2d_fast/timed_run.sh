#!/bin/bash
# Times the walk from 2D to Succ 90 % (issue 13) on an otherwise idle
# machine: trains CONFIG from a fresh start for MINUTES of wall time,
# keeps a copy of every checkpoint as it is written (ckpt_<samples>.pt),
# then evaluates each copy as eval_curve.sh does and prints the first
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
timeout -s INT "${minutes}m" /tmp/timed_run_mimic2d train "$config" > "$dir.log" 2>&1 &
trainer=$!
last=""
snapshot() {  # copies checkpoint.pt if it changed since the last copy
  [ -f "$dir/checkpoint.pt" ] || return 0
  local stamp samples
  stamp=$(stat -c %Y "$dir/checkpoint.pt")
  [ "$stamp" != "$last" ] || return 0
  # Named by the samples the checkpoint holds (the log runs on meanwhile).
  cp "$dir/checkpoint.pt" "$dir/snapshot.pt"
  samples=$(/tmp/timed_run_mimic2d checkpoint info "$dir/snapshot.pt" |
    sed -n 's/.*trained: \([0-9]*\) samples.*/\1/p')
  mv "$dir/snapshot.pt" "$dir/ckpt_$samples.pt"
  last=$stamp
}
while kill -0 "$trainer" 2>/dev/null; do
  snapshot
  sleep 5
done
wait "$trainer" || true
snapshot  # the checkpoint written on the stop
docs/experiments/walk2d_fast/eval_curve.sh "$dir" "$variant" | tee "$dir/eval_curve.csv"
awk -F, '$4 >= 0.9 { printf "first Succ >= 0.9: %s samples, %.1f min of training\n", $2, $3 / 60; found = 1; exit }
         END { if (!found) print "Succ 0.9 not reached" }' "$dir/eval_curve.csv"
