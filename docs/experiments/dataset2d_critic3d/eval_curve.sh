#!/bin/bash
# Evaluates every ckpt_<samples>.pt of a dataset run (kept while training by
# `train --keep-checkpoints` in RUN/checkpoints/) with the table's protocol
# (docs/results.md): the ten training clips, clean, from the fit's starts and
# cameras, one rollout per view from each clip's first frame to its end (40
# rollouts); the truth is read by `eval --truth` for E3D only. Prints rows of
# eval_curve.csv: variant,samples,succ_pct,e2d_px,e3d_root_rel_mm,pa_mpjpe_mm,mean_frames.
#   docs/experiments/dataset2d_critic3d/eval_curve.sh runs/dataset2d_critic3d critic3d \
#     >> docs/experiments/dataset2d_critic3d/eval_curve.csv
# A single checkpoint file instead of a run folder evaluates that one (its
# eval JSON is cached beside it, as <checkpoint>.eval.json).
# MIMIC2D names the binary (default build/mimic2d), DATA the bundles' folder
# (default runs/dataset, scripts/make_dataset.sh). TRUTH=1 evaluates a 3D-GT
# run instead (configs/dataset3d_gt.yaml): the truth bundles, with the truth's
# starts and the true cameras, as the table's 3D-GT row. NOISY=1 evaluates on
# the noisy 2D instead (the <clip>_noisy bundles, fitted on it; eval JSONs
# named eval_noisy_<samples>.json).
set -euo pipefail
mimic2d=${MIMIC2D:-build/mimic2d}
data=${DATA:-runs/dataset}
target=$1 variant=$2
clips="walk jog run kick punch jump dance_a stealthy_walk zombie_walk spin"
noisy="" tag=""
if [ "${NOISY:-0}" = 1 ]; then noisy=_noisy tag=noisy_; fi
args=()
if [ "${TRUTH:-0}" = 1 ]; then
  for clip in $clips; do args+=(--bundle "$data/${clip}${noisy}_truth.json"); done
  args+=(--starts truth --cameras truth)
else
  for clip in $clips; do args+=(--bundle "$data/$clip$noisy.json"); done
  args+=(--truth)
  for clip in $clips; do args+=("$data/${clip}${noisy}_truth.json"); done
fi

# evaluate CHECKPOINT JSON SAMPLES: one row (the eval JSON is cached).
evaluate() {
  [ -f "$2" ] || "$mimic2d" eval "$1" "${args[@]}" --episodes 1 --episode-s 10 \
    -o "$2" > /dev/null
  /usr/bin/python3 -c "import json; a=json.load(open('$2'))['all']; print('%s,%s,%.1f,%.1f,%.0f,%.0f,%.1f' % ('$variant', '$3', 100 * a['succ'], a['e2d_px'], a['e3d_root_mm'], a['e3d_pa_mm'], a['mean_frames']))"
}

if [ -f "$target" ]; then
  samples=$("$mimic2d" checkpoint info "$target" | awk '$1 == "trained:" {print $2}')
  evaluate "$target" "${target%.pt}.${tag}eval.json" "$samples"
  exit 0
fi
kept=$target/checkpoints
# In order of samples (sorted on the file name alone: the folder may hold _).
for name in $(cd "$kept" && printf '%s\n' ckpt_*.pt | sort -t_ -k2 -n); do
  n=$(basename "$name" .pt | cut -d_ -f2)
  evaluate "$kept/$name" "$target/eval_$tag$n.json" "$n"
done
