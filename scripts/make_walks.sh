#!/bin/bash
# The walk family for the generator's tracker (issue 16, docs/generation.md
# "The tracker fed by the stream"): the long DeepMimic walks the generator
# learns from (configs/gen/walks.yaml), each seen by 4 cameras that follow
# the walker's root (the dolly of configs/gen/walks.yaml and of generate
# --policy's rollouts; azimuths 30/120/210/300 deg, elevation 15 deg, the
# middle of the generator's 0-30, 4.5 m, focal 1000 px), stripped to their
# 2D and fitted view by view with the focal known: a user's four following
# videos per walk, fitted with configs/fit/root_dolly.yaml (the camera's
# centre sways with every step; until 2026-12-05 the default camera
# smoothness tilted 25 of the 36 views' worlds 14-35 deg). (Until
# 2026-12-04: elevation 10 deg and the 1-s path.)
#
#   [FIT_THREADS=N] [ELEVATION=deg] [TILT=known|rig] scripts/make_walks.sh [OUT_DIR] [WALK...]
#   (default runs/walks, all nine; the fit's threads, default 2; TILT=known:
#   the cameras' tilt given to the fit as the focal is, pitch ELEVATION and
#   roll 0, held: docs/fit.md "A known tilt"; TILT=rig: each walk's four
#   following views fitted together as one rig, every camera's tilt
#   estimated from the 2D: docs/fit.md "A rig"; default estimated, each
#   view alone)
#
# Writes OUT_DIR/<walk>_truth.json (the measurement's side), <walk>_2d.json
# (stripped) and <walk>.json (the fit's estimate: what training reads).
# Walks come from $MIMIC2D_SHARED_DATA (default ../shared/data)/deepmimic/
# motions/long; they stay there (MIT, but not carried by the repository).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-runs/walks}
shift || true
shared=${MIMIC2D_SHARED_DATA:-../shared/data}
long="$shared/deepmimic/motions/long"
# shellcheck source=scripts/private_binary.sh
source scripts/private_binary.sh
private_binary  # $bin: a copy, so a rebuild meanwhile does not fail it
mkdir -p "$out"
tilt=()
case ${TILT:-estimated} in
  known) tilt=(--tilt "${ELEVATION:-15},0") ;;
  rig) tilt=(--rig) ;;
  estimated) ;;
  *) echo "make_walks: TILT must be known, rig or estimated" >&2; exit 2 ;;
esac
walks=("$@")
if [ ${#walks[@]} -eq 0 ]; then
  walks=(long_walk1 long_walk1_mirror long_walk2 long_walk2_mirror long_walk3
         long_walk3_mirror long_zombie stealthy_walk0 stealthy_walk1)
fi

for walk in "${walks[@]}"; do
  motion="$long/humanoid3d_$walk.txt"
  [ -f "$motion" ] || { echo "make_walks: $motion not found" >&2; exit 1; }
  [ -f "$out/$walk.json" ] && { echo "kept $out/$walk.json"; continue; }
  $bin clip from-motion "$motion" --views 4 --elevation "${ELEVATION:-15}" \
    --distance 4.5 --focal 1000 --follow --follow-smoothing 0 -o "$out/${walk}_truth.json" > /dev/null
  $bin clip strip "$out/${walk}_truth.json" -o "$out/${walk}_2d.json" \
    > /dev/null
  if $bin fit "$out/${walk}_2d.json" --camera moving --focal 1000 "${tilt[@]}" \
    --config configs/fit/root_dolly.yaml --threads "${FIT_THREADS:-2}" \
    --quiet -o "$out/$walk.json" > "$out/${walk}_fit.log" 2>&1;
  then
    echo "fitted $walk: $(grep -c 'all frames converged' "$out/${walk}_fit.log") of 4 views converged on every frame"
  else
    echo "left out $walk: $(tail -n 1 "$out/${walk}_fit.log")"
  fi
done
