#!/bin/bash
# Measures a walk-family tracker checkpoint two ways (docs/generation.md 4b,
# "Servo or whole-PD torque limits for the walks"):
#   1. the issue's protocol: the walk generator's streams (runs/gen_walks,
#      each of its 9 motions once, azimuths 30 and 210 deg at elevation 15,
#      60 s, starts and cameras from the fit of each stream's first 2 s);
#   2. the training walks themselves (runs/walks, the fits' starts and
#      cameras, 2 rollouts of 10 s per view), per walk.
# No 3D truth is read by either.
#   [FIT_CONFIG=configs/fit/root_dolly.yaml] [DRAWS=N] [START_FIT_S=s] \
#     [START_AT_S=s] docs/experiments/walks2d_pd/measure.sh CHECKPOINT OUT_PREFIX
# FIT_CONFIG: the FitOptions of the streams' start fits (default: the
# defaults, as every figure before 2026-12-05 was measured).
# DRAWS: how many draws of the 18 streams (default 1: seeds 1-9, as every
# figure before 2026-12-06's sixth session; draw d uses seeds 9d+1...9d+9,
# logged as OUT_PREFIX_generated[_d].log, every rollout's per-frame errors in
# OUT_PREFIX_frames[_d].csv). One draw moves the count by 2-3.
# FIRST_DRAW: the first draw d (default 0); FIRST_DRAW=4 DRAWS=4 measures
# seeds 37-72, streams no figure before 2026-12-07's seventh session saw.
# START_FIT_S, START_AT_S: generate's --start-fit-s (the stream's first
# seconds fitted, default 2) and --start-at-s (where the rollout starts,
# default the middle of the fitted seconds); figures before 2026-12-07 are
# of the defaults.
# START_TILT: generate's --start-tilt: view (the default since 2026-12-07's
# second session: the start fits hold --view's tilt) or fit (estimated, as
# every figure before it).
# MIMIC2D: the binary (default build/mimic2d; a copy lets the build change
# while a measure runs).
set -euo pipefail
cd "$(dirname "$0")/../../.."
checkpoint=$1 out=$2
start_options=()
[ -n "${FIT_CONFIG:-}" ] && start_options=(--fit-config "$FIT_CONFIG")
[ -n "${START_FIT_S:-}" ] && start_options+=(--start-fit-s "$START_FIT_S")
[ -n "${START_AT_S:-}" ] && start_options+=(--start-at-s "$START_AT_S")
[ -n "${START_TILT:-}" ] && start_options+=(--start-tilt "$START_TILT")
first_draw=${FIRST_DRAW:-0}
for ((draw = first_draw; draw < first_draw + ${DRAWS:-1}; ++draw)); do
  suffix=""
  [ "$draw" -gt 0 ] && suffix="_$draw"
  ${MIMIC2D:-build/mimic2d} generate runs/gen_walks --seconds 60 --view 30,15,4.5 \
    "${start_options[@]}" --policy "$checkpoint" --generations 9 --each-motion --azimuths 30,210 \
    --seed $((9 * draw + 1)) -o "${out}_generated${suffix}.json" \
    --frames "${out}_frames${suffix}.csv" \
    > "${out}_generated${suffix}.log" 2>&1
  grep -E "generation|^Succ" "${out}_generated${suffix}.log"
done
${MIMIC2D:-build/mimic2d} eval "$checkpoint" --episodes 2 --episode-s 10 \
  -o "${out}_eval.json" > "${out}_eval.log" 2>&1
tail -n 45 "${out}_eval.log"
