#!/bin/bash
# Evaluates every kept checkpoint of the run-alone 3D-GT trial
# (config_3d.yaml, trained with --keep-checkpoints) on the dataset's run
# with the truth's starts and the true cameras, as the 2D trial's
# eval_curve.csv does: one rollout per view from the clip's first frame
# (frames held per view, Succ), and 20 ten-frame windows per view spread
# over the clip (Succ per view and over all). Prints rows of
# eval_curve_3d.csv:
#   docs/experiments/run_only/eval_curve_3d.sh runs/exp/run_only_3d \
#     > docs/experiments/run_only/eval_curve_3d.csv
# MIMIC2D names the binary (default build/mimic2d), DATA the bundles' folder
# (default runs/dataset, scripts/make_dataset.sh). STARTS=estimate evaluates
# from the fit's starts and cameras instead (runs/dataset/run.json; the
# table's protocol, for the 2D trials; the windows' columns are then the
# fit's). CLIP names another of the dataset's clips (default run; the
# clip-alone trials, docs/experiments/clip_alone). Eval JSONs are cached in
# the run folder, per STARTS.
set -euo pipefail
mimic2d=${MIMIC2D:-build/mimic2d}
data=${DATA:-runs/dataset}
starts=${STARTS:-truth}
clip=${CLIP:-run}
run=$1
case $starts in
  truth) args=(--bundle "$data/${clip}_truth.json" --starts truth --cameras truth) ;;
  estimate) args=(--bundle "$data/${clip}.json" --starts estimate --cameras estimate) ;;
  *) echo "eval_curve_3d: STARTS must be truth or estimate, not $starts" >&2; exit 2 ;;
esac

echo "samples,first_frame_frames_view0,view1,view2,view3,first_frame_succ_pct,windows_${starts}_succ_pct_view0,view1,view2,view3,windows_${starts}_succ_pct"
kept=$run/checkpoints
for name in $(cd "$kept" && printf '%s\n' ckpt_*.pt | sort -t_ -k2 -n); do
  n=$(basename "$name" .pt | cut -d_ -f2)
  first=$run/eval_first_${starts}_$n.json windows=$run/eval_windows_${starts}_$n.json
  [ -f "$first" ] || "$mimic2d" eval "$kept/$name" "${args[@]}" \
    --episodes 1 --episode-s 10 -o "$first" > /dev/null
  [ -f "$windows" ] || "$mimic2d" eval "$kept/$name" "${args[@]}" \
    --episodes 20 --episode-s 0.34 -o "$windows" > /dev/null
  /usr/bin/python3 - "$n" "$first" "$windows" <<'PY'
import json, sys
n, first, windows = sys.argv[1:]
f, w = json.load(open(first)), json.load(open(windows))
def views(d):
    return sorted((r for r in d['rows'] if r['view'] != 'all'), key=lambda r: r['view'])
frames = [str(r['rollouts'][0]['frames']) for r in views(f)]
wins = ['%.1f' % (100 * r['succ']) for r in views(w)]
print(','.join([n] + frames + ['%.1f' % (100 * f['all']['succ'])] + wins +
               ['%.1f' % (100 * w['all']['succ'])]))
PY
done
