#!/bin/bash
# The paper's Animal rows on our dog (docs/quadruped.md), from trained
# checkpoints: ours (configs/dog2d.yaml) against the two-stage Sfv* w/ our
# fit (configs/dog_sfv.yaml), both trained from 2D only; then ours given
# 1, 2 and 3 views at once (zero-shot multi-view tracking, the true
# cameras and starts). Columns Succ, E2D, E3D global, root-relative and
# Procrustes-aligned, Jitter.
#
#   bench/dog_table.sh [DATASET_DIR] [OUT_DIR]
#       (defaults runs/dog, runs/dog_table)
#
# Needs scripts/make_dog_dataset.sh's bundles (<clip>.json, the fit's
# estimate; <clip>_truth.json, read for E3D only and by the true-camera
# rows). OURS_CHECKPOINT and SFV_CHECKPOINT name other checkpoints than
# runs/dog2d and runs/dog_sfv; a missing checkpoint's rows say so. DOG_CLIPS
# names other clips (default "trot pace spin"). Every rollout starts at a
# clip's first frame and runs to its end (the clips are 2 s): one rollout
# per view. Prints a Markdown table; each row's eval table and JSON go to
# OUT_DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-runs/dog}
out=${2:-runs/dog_table}
# shellcheck source=bench/table_row.sh
source bench/table_row.sh
mkdir -p "$out"

clips=${DOG_CLIPS:-trot pace spin}
ours=${OURS_CHECKPOINT:-runs/dog2d/checkpoint.pt}
sfv=${SFV_CHECKPOINT:-runs/dog_sfv/checkpoint.pt}

# flags SUFFIX: --bundle flags for the clips' SUFFIX bundles.
flags() {
  local clip
  for clip in $clips; do
    [ -f "$data/$clip$1.json" ] || {
      echo "dog_table: $data/$clip$1.json not found (scripts/make_dog_dataset.sh $data)" >&2
      return 1
    }
    printf -- "--bundle %s/%s%s.json " "$data" "$clip" "$1"
  done
}
# truths: the clips' truth, for the from-2D rows' E3D only (eval --truth:
# the policy and its task never read it).
truths() {
  local clip
  printf -- "--truth "
  for clip in $clips; do printf -- "%s/%s_truth.json " "$data" "$clip"; done
}
fitted=$(flags "")
truth=$(flags _truth)
truth_of_fitted=$(truths)
label=$(echo "$clips" | tr ' ' ',')

# row NAME CHECKPOINT TAG [EVAL FLAGS...]: one row on the clean 2D.
row() {
  local name=$1 checkpoint=$2 tag=$3
  shift 3
  table_row "$name" "$label" clean "$checkpoint" "$out/$tag" \
    --episodes 1 --episode-s 10 "$@"
}

table_header
# shellcheck disable=SC2086
row "ours, 1 view, from 2D (fit's starts and cameras)" "$ours" ours_2d \
  $fitted $truth_of_fitted
# shellcheck disable=SC2086
row "Sfv* w/ our fit (fit's starts and cameras)" "$sfv" sfv_2d \
  $fitted $truth_of_fitted
for views in 1 2 3; do
  # shellcheck disable=SC2086
  row "ours, $views view(s), truth starts, true cameras" "$ours" \
    "ours_truth_${views}views" $truth --starts truth --cameras truth \
    --views "$views"
done
