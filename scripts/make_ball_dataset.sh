#!/bin/bash
# The ball's dataset (docs/ball.md): DeepMimic's walk (4 s, looped) with a
# soccer ball put in the path of its fastest low foot, the ball's flight
# simulated with the humanoid replaying the walk (clip from-motion --ball
# auto), seen by 4 static cameras (1920x1080, focal 1000 px, 6 m from the
# middle of the path, elevations 5-25 deg) as COCO-17 keypoints plus the
# ball's centre, then stripped to its 2D and fitted view by view: what a
# user with four calibrated videos and a person-and-ball detector has (the
# intrinsics known, `--focal`).
#
#   scripts/make_ball_dataset.sh [OUT_DIR]   (default runs/ball)
#
# Writes OUT_DIR/walk_truth.json (for measurement only), walk_2d.json
# (stripped), walk.json (the fit's estimate, the ball placed on the floor
# under the fitted cameras; what configs/ball2d.yaml trains on) and the
# fit's log, walk_fit.log, ending with its accuracy against the truth (the
# ball's error included). Reads only the repository's own walk clip (MIT).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-runs/ball}
# shellcheck source=scripts/private_binary.sh
source scripts/private_binary.sh
private_binary  # $bin: a copy, so a rebuild meanwhile does not fail it
mkdir -p "$out"

if [ ! -f "$out/walk_2d.json" ]; then
  $bin clip from-motion assets/motions/deepmimic/humanoid3d_walk.txt \
    --ball auto --duration 4 --views 4 --elevation 5 --elevation-span 20 \
    --distance 6 --focal 1000 --aim middle -o "$out/walk_truth.json" |
    grep '^ball:'
  $bin clip strip "$out/walk_truth.json" -o "$out/walk_2d.json" > /dev/null
fi
if [ ! -f "$out/walk.json" ]; then
  if $bin fit "$out/walk_2d.json" --camera static --focal 1000 --quiet \
    --truth "$out/walk_truth.json" -o "$out/walk.json" \
    > "$out/walk_fit.log" 2>&1; then
    echo "fitted walk: $(grep -m 1 '^mean over the views' "$out/walk_fit.log")"
  else
    echo "make_ball_dataset: the fit failed, see $out/walk_fit.log" >&2
    exit 1
  fi
fi
