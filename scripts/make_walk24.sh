#!/bin/bash
# The straight walk seen from the walk generator's 24 views (configs/gen/
# walk.yaml: 8 azimuths x elevations 5/10/15 deg, 4.5 m, focal 1000 px,
# cameras following the root), stripped to their 2D and fitted view by view
# with the focal known: the data of a walk tracker that covers every view
# the generator generates (the walk2d tracker knows elevation 10 deg only;
# docs/generation.md 4b). About a minute of fitting per view on one thread (41 s on 2).
#
#   [FIT_THREADS=N] scripts/make_walk24.sh [OUT_DIR]   (default runs/walk24)
#
# Writes OUT_DIR/el<E>_truth.json (the measurement's side), el<E>_2d.json
# (stripped) and el<E>_fitted.json (what configs/walk24_2d.yaml trains on).
# An elevation already fitted is kept, so a killed run resumes.
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-runs/walk24}
# shellcheck source=scripts/private_binary.sh
source scripts/private_binary.sh
private_binary  # $bin: a copy, so a rebuild meanwhile does not fail it
mkdir -p "$out"
for el in 10 5 15; do
  if [ ! -f "$out/el${el}_2d.json" ]; then
    "$bin" clip from-motion assets/motions/deepmimic/humanoid3d_walk.txt \
      --views 8 --elevation "$el" --duration 20 --follow --follow-smoothing 0 \
      --loop-heading straight -o "$out/el${el}_truth.json"
    "$bin" clip strip "$out/el${el}_truth.json" -o "$out/el${el}_2d.json"
  fi
  if [ ! -f "$out/el${el}_fitted.json" ]; then
    "$bin" fit "$out/el${el}_2d.json" --camera moving --focal 1000 \
      --threads "${FIT_THREADS:-2}" -o "$out/el${el}_fitted.json"
  fi
done
