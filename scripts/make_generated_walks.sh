#!/bin/bash
# Generated walks to train the walk-family tracker on (issue 16,
# docs/generation.md 4b, "Trained on generated walks"): the walk generator
# (runs/gen_walks) draws each of its nine motions under the four training
# azimuths (30/120/210/300 deg, elevation 15 deg, 4.5 m, focal 1000 px, the
# camera on the root as in generate --policy), and each clip is fitted as a
# user's 2D would be (--camera moving, the focal known,
# configs/fit/root_dolly.yaml): the fit gives the starts and cameras, there
# is no 3D. Seeds start at SEED_BASE (default 1001), far from the measure's
# 1-18 (docs/experiments/walks2d_pd/measure.sh), so that no measured stream
# is trained on.
#
#   [FIT_THREADS=N] [SECONDS_PER_CLIP=s] [SEED_BASE=n] [TILT=view] \
#     scripts/make_generated_walks.sh [OUT_DIR] [MOTION...]
#   (default runs/gen_clips, motions 0-8; 20 s per clip; the fit's threads,
#   default 2)
# TILT=view: the fit holds the chosen view's tilt (pitch 15 deg, roll 0), as
# generate --policy's start fits do (--start-tilt view: a generated view is
# chosen, not filmed; docs/fit.md "A known tilt"); default: estimated.
#
# Writes OUT_DIR/m<motion>_az<azimuth>_2d.json (the generated 2D) and
# OUT_DIR/m<motion>_az<azimuth>.json (its fit: what training reads).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-runs/gen_clips}
shift || true
[ -f runs/gen_walks/prior.pt ] || {
  echo "make_generated_walks: runs/gen_walks/prior.pt not found; copy" \
    "assets/runs/gen_walks/{tokenizer.pt,prior.pt} there" >&2
  exit 1
}
# shellcheck source=scripts/private_binary.sh
source scripts/private_binary.sh
private_binary  # $bin: a copy, so a rebuild meanwhile does not fail it
mkdir -p "$out"
motions=("$@")
[ ${#motions[@]} -eq 0 ] && motions=(0 1 2 3 4 5 6 7 8)
azimuths=(30 120 210 300)
tilt=()
case ${TILT:-} in
  "") ;;
  view) tilt=(--tilt "15,0") ;;
  *) echo "make_generated_walks: TILT must be view or unset" >&2; exit 2 ;;
esac

for motion in "${motions[@]}"; do
  for a in "${!azimuths[@]}"; do
    azimuth=${azimuths[$a]}
    name="m${motion}_az${azimuth}"
    [ -f "$out/$name.json" ] && { echo "kept $out/$name.json"; continue; }
    seed=$((${SEED_BASE:-1001} + 4 * motion + a))
    $bin generate runs/gen_walks --seconds "${SECONDS_PER_CLIP:-20}" \
      --view "$azimuth,15,4.5" --focal 1000 --motion "$motion" \
      --seed "$seed" -o "$out/${name}_2d.json" > /dev/null
    if $bin fit "$out/${name}_2d.json" --camera moving --focal 1000 "${tilt[@]}" \
      --config configs/fit/root_dolly.yaml --threads "${FIT_THREADS:-2}" \
      --quiet -o "$out/$name.json" > "$out/${name}_fit.log" 2>&1; then
      echo "fitted $name (seed $seed): $(grep -c 'all frames converged' \
        "$out/${name}_fit.log") of 1 view converged on every frame"
    else
      echo "left out $name (seed $seed): $(tail -n 1 "$out/${name}_fit.log")"
    fi
  done
done
