#!/bin/bash
# The paper's main table on our data (issue 14, docs/results.md), from
# trained checkpoints: rows 3D-GT / ours 1 view (from 2D) / ours 1, 2, 3
# views (true cameras) / Sfv*; columns Succ, E2D, E3D global, root-relative
# and Procrustes-aligned, Jitter; on the training clips and the unseen ones,
# clean and noisy 2D.
#
#   bench/dataset_table.sh [DATASET_DIR] [OUT_DIR]
#       (defaults runs/dataset, runs/dataset_table)
#
# Needs scripts/make_dataset.sh's bundles and the checkpoints of
# configs/dataset2d.yaml, dataset3d_gt.yaml and dataset_sfv.yaml (a missing
# checkpoint's rows are skipped and say so; OURS_CHECKPOINT, GT_CHECKPOINT
# and SFV_CHECKPOINT name others). Every rollout starts at a
# clip's first frame and runs to its end (clips are 0.8-4.4 s): one rollout
# per view. Prints a Markdown table; every row's eval JSON goes to OUT_DIR.
# On a rig's fits (scripts/make_dataset.sh --rig: each clip's views in one
# world) the 2- and 3-view rows are also made from 2D, under the rig fit's
# starts and cameras.
# SUCCESS_MEASURE=mean_keypoint judges Succ by a frame's mean keypoint
# error instead of its worst (eval --success-measure; docs/tracking.md).
set -euo pipefail
cd "$(dirname "$0")/.."
data=${1:-runs/dataset}
out=${2:-runs/dataset_table}
# shellcheck source=bench/table_row.sh
source bench/table_row.sh
mkdir -p "$out"

train_clips="walk jog run kick punch jump dance_a stealthy_walk zombie_walk spin"
# The unseen clips the fit could estimate (scripts/make_dataset.sh leaves
# out the crawl and the get-up: their fits do not converge).
unseen_clips="dance_spin roll"

# The checkpoints (each overridable, e.g. to table a variant's run).
ours=${OURS_CHECKPOINT:-runs/dataset2d/checkpoint.pt}
gt=${GT_CHECKPOINT:-runs/dataset3d_gt/checkpoint.pt}
sfv=${SFV_CHECKPOINT:-runs/dataset_sfv/checkpoint.pt}
measure=${SUCCESS_MEASURE:-worst_keypoint}
# 1 when the fits are a rig's (the estimate's one_world), else 0.
rig=$(/usr/bin/python3 -c "import json, sys; print(int(json.load(open(sys.argv[1])).get('estimate', {}).get('one_world', False)))" "$data/walk.json" 2>/dev/null || echo 0)

# bundles SPLIT SUFFIX: --bundle flags for the split's clips.
bundles() {
  local clips=$train_clips
  [ "$1" = unseen ] && clips=$unseen_clips
  for clip in $clips; do printf -- "--bundle %s/%s%s.json " "$data" "$clip" "$2"; done
}

# truths SPLIT SUFFIX: the same clips' truth, for the from-2D rows' E3D only (eval --truth: the
# policy and its task never read it).
truths() {
  local clips=$train_clips
  [ "$1" = unseen ] && clips=$unseen_clips
  printf -- "--truth "
  for clip in $clips; do printf -- "%s/%s%s_truth.json " "$data" "$clip" "$2"; done
}

# row NAME CHECKPOINT SPLIT NOISE SUFFIX [EVAL FLAGS...]: one table row.
row() {
  local name=$1 checkpoint=$2 split=$3 noise=$4 suffix=$5
  shift 5
  local tag noisy=""
  tag=$(echo "$name-$split-$noise" | tr ' ,*/' '____')
  [ "$noise" = noisy ] && noisy=_noisy
  # shellcheck disable=SC2046
  table_row "$name" "$split" "$noise" "$checkpoint" "$out/$tag" \
    $(bundles "$split" "$noisy$suffix") --episodes 1 --episode-s 10 \
    --success-measure "$measure" "$@"
}

table_header
for split in train unseen; do
  for noise in clean noisy; do
    row "3D-GT (truth starts, true cameras)" "$gt" "$split" "$noise" _truth
    # shellcheck disable=SC2046
    row "ours, 1 view, from 2D (fit's starts and cameras)" "$ours" "$split" "$noise" "" \
      $(truths "$split" "$([ "$noise" = noisy ] && echo _noisy)")
    for views in 1 2 3; do
      row "ours, $views view(s), truth starts, true cameras" "$ours" "$split" "$noise" _truth \
        --starts truth --cameras truth --views "$views"
    done
    if [ "$rig" = 1 ]; then
      for views in 2 3; do
        # shellcheck disable=SC2046
        row "ours, $views views, from 2D (rig fit's starts and cameras)" "$ours" "$split" "$noise" "" \
          --views "$views" $(truths "$split" "$([ "$noise" = noisy ] && echo _noisy)")
      done
    fi
    # shellcheck disable=SC2046
    row "Sfv* w/ our fit (fit's starts and cameras)" "$sfv" "$split" "$noise" "" \
      $(truths "$split" "$([ "$noise" = noisy ] && echo _noisy)")
  done
done
