#!/bin/bash
# The dataset of issue 14 (docs/results.md): DeepMimic humanoid clips, each
# seen by an AIST++-like rig of 4 static cameras (1920x1080, focal 1400 px,
# elevations 0-30 deg, 3.5-6 m away, the azimuths turned per clip), then
# stripped to their 2D and fitted view by view: what a user with four
# calibrated videos per clip has (the intrinsics known, `--focal`).
#
#   scripts/make_dataset.sh [--rig] [OUT_DIR [FIT_CONFIG]]   (default runs/dataset)
#
# --rig: each clip's four views fitted as one synchronized rig (`fit --rig`:
# one body, the cameras placed in one world; docs/fit.md, "A rig") instead
# of view by view. MAKE_DATASET_JOBS: fits at a time (default 2).
#
# FIT_CONFIG: FitOptions as YAML for every fit (docs/fit.md, "Settings");
# default: the fit's defaults.
#
# Writes OUT_DIR/<clip>_truth.json (the measurement's side: eval reads its
# ground truth for E3D only), <clip>_2d.json (stripped) and <clip>.json (the
# fit's estimate; what training and eval read), and the same with detector
# noise (Gaussian 4 px, 5 % of keypoints dropped, seed 11) as
# <clip>_noisy_truth.json, _noisy_2d.json, _noisy.json. Each fit's log,
# <name>_fit.log, ends with its accuracy against the truth (`fit --truth`:
# measured after the fit, which never reads it). A clip the fit
# cannot estimate (more than a quarter of a view's frames unconverged, e.g.
# the crawl) is reported and left out. Clips come from
# $MIMIC2D_SHARED_DATA (default ../shared/data)/deepmimic/motions.
set -euo pipefail
cd "$(dirname "$0")/.."
rig=()
if [ "${1:-}" = --rig ]; then rig=(--rig); shift; fi
parallel=${MAKE_DATASET_JOBS:-2}
out=${1:-runs/dataset}
fit_config=()
if [ -n "${2:-}" ]; then
  [ -f "$2" ] || { echo "make_dataset: fit config $2 not found" >&2; exit 1; }
  fit_config=(--config "$2")
fi
shared=${MIMIC2D_SHARED_DATA:-../shared/data}
motions="$shared/deepmimic/motions"
# shellcheck source=scripts/private_binary.sh
source scripts/private_binary.sh
private_binary  # $bin: a copy, so a rebuild meanwhile does not fail it
mkdir -p "$out"

train_clips="walk jog run kick punch jump dance_a stealthy_walk zombie_walk spin"
unseen_clips="crawl dance_spin roll getup_faceup"

make_one() {  # clip index [noisy]
  local clip=$1 index=$2 noise=() name=$1
  if [ "${3:-}" = noisy ]; then
    noise=(--noise-px 4 --drop 0.05 --seed 11)
    name=${clip}_noisy
  fi
  local motion="$motions/humanoid3d_$clip.txt"
  [ -f "$motion" ] || { echo "make_dataset: $motion not found" >&2; return 1; }
  # Odd clips put the high camera close and the low one far.
  local elevation=0 elevation_span=30
  if (( index % 2 )); then elevation=30; elevation_span=-30; fi
  local azimuth=$(( (index * 37) % 360 ))
  # Done: fitted, or refused by an earlier fit (its log ends in an error).
  # A fit stopped part-way left neither, and is made again.
  [ -f "$out/${name}.json" ] && return 0
  if grep -q '^error' "$out/${name}_fit.log" 2>/dev/null; then
    echo "left out $name (as before): $(grep -m 1 '^error' "$out/${name}_fit.log")"
    return 0
  fi
  if [ ! -f "$out/${name}_2d.json" ]; then
    $bin clip from-motion "$motion" --views 4 --first-azimuth "$azimuth" \
      --elevation "$elevation" --elevation-span "$elevation_span" \
      --distance 3.5 --distance-span 2.5 --focal 1400 --aim middle \
      "${noise[@]}" -o "$out/${name}_truth.json" > /dev/null
    $bin clip strip "$out/${name}_truth.json" -o "$out/${name}_2d.json" \
      > /dev/null
  fi
  if $bin fit "$out/${name}_2d.json" --camera static --focal 1400 --quiet \
    "${rig[@]}" "${fit_config[@]}" --truth "$out/${name}_truth.json" \
    -o "$out/${name}.json" > "$out/${name}_fit.log" 2>&1; then
    echo "fitted $name"
  else
    echo "left out $name: $(grep -m 1 '^error' "$out/${name}_fit.log" ||
      tail -n 1 "$out/${name}_fit.log")"
  fi
}

# $parallel fits at a time (one solver thread each).
jobs_started=0
for variant in clean noisy; do
  index=0
  for clip in $train_clips $unseen_clips; do
    make_one "$clip" "$index" "$variant" &
    index=$((index + 1))
    jobs_started=$((jobs_started + 1))
    if (( jobs_started % parallel == 0 )); then wait; fi
  done
done
wait
