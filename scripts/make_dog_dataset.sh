#!/bin/bash
# The dog's dataset (docs/quadruped.md): DeepMimic's three dog3d clips
# (trot, pace, spin; 2 s each, looped), each seen by 4 static cameras
# (1920x1080, focal 1400 px, 4.5 m away, elevations 5-25 deg) as AP-10K
# keypoints, then stripped to their 2D and fitted view by view with the dog
# character: what a user with four calibrated videos per clip and an animal
# keypoint detector has (the intrinsics known, `--focal`).
#
#   scripts/make_dog_dataset.sh [--rig] [OUT_DIR]   (default runs/dog)
#
# --rig: each clip's four views fitted as one synchronized rig (`fit --rig`,
# docs/fit.md, "A rig") instead of view by view.
#
# Writes OUT_DIR/<clip>_truth.json (for measurement only: eval reads its
# ground truth for E3D), <clip>_2d.json (stripped) and <clip>.json (the
# fit's estimate; what configs/dog2d.yaml trains on), and each fit's log,
# <clip>_fit.log, ending with its accuracy against the truth (`fit
# --truth`: measured after the fit, which never reads it). The clips' source
# may be non-commercial, so they are not in the repository: they are read
# from $MIMIC2D_SHARED_DATA (default ../shared/data)/deepmimic/motions.
set -euo pipefail
cd "$(dirname "$0")/.."
rig=()
if [ "${1:-}" = --rig ]; then rig=(--rig); shift; fi
out=${1:-runs/dog}
shared=${MIMIC2D_SHARED_DATA:-../shared/data}
motions="$shared/deepmimic/motions"
# shellcheck source=scripts/private_binary.sh
source scripts/private_binary.sh
private_binary  # $bin: a copy, so a rebuild meanwhile does not fail it
character=characters/dog.yaml
mkdir -p "$out"

make_one() {  # clip
  local clip=$1
  local motion="$motions/dog3d_$clip.txt"
  [ -f "$motion" ] || { echo "make_dog_dataset: $motion not found" >&2; return 1; }
  [ -f "$out/$clip.json" ] && return 0
  if [ ! -f "$out/${clip}_2d.json" ]; then
    $bin clip from-motion "$motion" --character "$character" --duration 2 \
      --views 4 --elevation 5 --elevation-span 20 --distance 4.5 \
      --focal 1400 --aim middle -o "$out/${clip}_truth.json" > /dev/null
    $bin clip strip "$out/${clip}_truth.json" -o "$out/${clip}_2d.json" \
      > /dev/null
  fi
  if $bin fit "$out/${clip}_2d.json" --character "$character" --camera static \
    --focal 1400 --quiet "${rig[@]}" --truth "$out/${clip}_truth.json" \
    -o "$out/$clip.json" > "$out/${clip}_fit.log" 2>&1; then
    echo "fitted $clip: $(grep -m 1 '^mean over the views' "$out/${clip}_fit.log")"
  else
    echo "make_dog_dataset: the fit of $clip failed, see $out/${clip}_fit.log" >&2
    return 1
  fi
}

for clip in trot pace spin; do make_one "$clip"; done
