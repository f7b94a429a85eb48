#!/bin/bash
# Evaluates every ckpt_<samples>.pt of a run folder (kept while training by
# `train --keep-checkpoints` in RUN/checkpoints/, or in RUN itself) with 10
# episodes x 10 s per view from the fit's starts and cameras, and prints
# eval_curves.csv rows: variant,samples,wall_time_s,succ,e2d_px,mean_frames.
#   docs/experiments/walk2d_fast/eval_curve.sh runs/exp/I substeps2_seed1 >> docs/experiments/walk2d_fast/eval_curves.csv
# MIMIC2D names the binary (default build/mimic2d).
set -e
mimic2d=${MIMIC2D:-build/mimic2d}
dir=$1; variant=$2
kept=$dir
[ -d "$dir/checkpoints" ] && kept=$dir/checkpoints
# In order of samples (sorted on the file name alone: the folder may hold _).
for name in $(cd "$kept" && printf '%s\n' ckpt_*.pt | sort -t_ -k2 -n); do
  c="$kept/$name"
  n=$(basename "$c" .pt | cut -d_ -f2)
  j="$dir/eval_$n.json"
  [ -f "$j" ] || "$mimic2d" eval "$c" --bundle runs/walk_fitted.json \
    --episodes 10 --episode-s 10 -o "$j" > /dev/null 2>&1
  w=$(awk -F, -v n="$n" '$2==n {printf "%.0f", $3}' "$dir/train_log.csv")
  /usr/bin/python3 -c "import json; a=json.load(open('$j'))['all']; print('%s,%s,%s,%.3f,%.1f,%.0f' % ('$variant', '$n', '$w', a['succ'], a['e2d_px'], a['mean_frames']))"
done
