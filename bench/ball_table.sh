#!/bin/bash
# The paper's Soccer Dribble rows on our ball (docs/ball.md), from trained
# checkpoints: ours (configs/ball2d.yaml) against the two-stage Sfv* w/ our
# fit (configs/ball_sfv.yaml), both trained from 2D only, from the fit's
# starts and cameras; ours over ten-frame windows; then ours given 1 and 3
# views at once with the truth's starts and the true cameras. Columns Succ,
# E2D, EO2D (the ball), E3D global, root-relative and Procrustes-aligned,
# Jitter.
#
#   bench/ball_table.sh [DATASET_DIR] [OUT_DIR]
#       (defaults runs/ball, runs/ball_table)
#
# Needs scripts/make_ball_dataset.sh's bundles (walk.json, the fit's
# estimate; walk_truth.json, read for E3D only and by the true-camera rows).
# OURS_CHECKPOINT and SFV_CHECKPOINT name other checkpoints than
# runs/ball2d and runs/ball_sfv; a missing checkpoint's rows say so. A
# rollout starts at the clip's first frame and runs to its end (4 s), one
# per view; the window row starts 20 rollouts of 10 frames per view spread
# over the clip. Prints a Markdown table; each row's eval table and JSON go
# to OUT_DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-runs/ball}
out=${2:-runs/ball_table}
# shellcheck source=bench/table_row.sh
source bench/table_row.sh
TABLE_OBJECTS=1
mkdir -p "$out"

ours=${OURS_CHECKPOINT:-runs/ball2d/checkpoint.pt}
sfv=${SFV_CHECKPOINT:-runs/ball_sfv/checkpoint.pt}
for bundle in "$data/walk.json" "$data/walk_truth.json"; do
  [ -f "$bundle" ] || {
    echo "ball_table: $bundle not found (scripts/make_ball_dataset.sh $data)" >&2
    exit 1
  }
done
# The from-2D rows read the truth for E3D only (eval --truth: the policy and
# its task never read it).
fitted=(--bundle "$data/walk.json" --truth "$data/walk_truth.json")
truth=(--bundle "$data/walk_truth.json" --starts truth --cameras truth)
whole=(--episodes 1 --episode-s 10)
windows=(--episodes 20 --episode-s 0.34)

table_header
table_row "ours, 1 view, from 2D (fit's starts and cameras)" walk clean \
  "$ours" "$out/ours_2d" "${fitted[@]}" "${whole[@]}"
table_row "Sfv* w/ our fit (fit's starts and cameras)" walk clean \
  "$sfv" "$out/sfv_2d" "${fitted[@]}" "${whole[@]}"
table_row "ours, 1 view, from 2D, ten-frame windows" walk clean \
  "$ours" "$out/ours_2d_windows" "${fitted[@]}" "${windows[@]}"
table_row "Sfv* w/ our fit, ten-frame windows" walk clean \
  "$sfv" "$out/sfv_2d_windows" "${fitted[@]}" "${windows[@]}"
for views in 1 3; do
  table_row "ours, $views view(s), truth starts, true cameras" walk clean \
    "$ours" "$out/ours_truth_${views}views" "${truth[@]}" "${whole[@]}" \
    --views "$views"
done
