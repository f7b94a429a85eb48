#!/bin/bash
# The paper's robustness tests on a ball checkpoint (docs/ball.md,
# "Robustness"): the fit's starts and cameras, one rollout per view from the
# first frame to the end (4 per evaluation), for the perturbation seeds 1-5
# (20 rollouts per test; the unperturbed test is deterministic, one
# evaluation). Prints CSV: variant,test,rollouts,succ_pct,e2d_px,eo2d_px,
# e3d_root_mm,pa_mpjpe_mm, averaged over the seeds' evaluations.
#   docs/experiments/ball_robust/eval.sh runs/exp/ball_robust/checkpoint.pt robust
# MIMIC2D names the binary (default build/mimic2d), DATA the bundles' folder
# (default runs/ball, scripts/make_ball_dataset.sh); the truth is read by
# `eval --truth` for E3D only. Each evaluation's JSON goes to $OUT (default
# a temporary folder).
set -euo pipefail
mimic2d=${MIMIC2D:-build/mimic2d}
data=${DATA:-runs/ball}
checkpoint=$1 variant=$2
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"

# run TEST SEEDS FLAGS...: evaluates once per seed, prints the mean row.
run() {
  local test=$1 seeds=$2
  shift 2
  local files=()
  for seed in $seeds; do
    local file="$out/${variant}_${test}_s$seed.json"
    "$mimic2d" eval "$checkpoint" --bundle "$data/walk.json" \
      --truth "$data/walk_truth.json" --episodes 1 --episode-s 10 \
      --perturbation-seed "$seed" "$@" -o "$file" > /dev/null
    files+=("$file")
  done
  /usr/bin/python3 - "$variant" "$test" "${files[@]}" <<'PY'
import json, sys
variant, test, files = sys.argv[1], sys.argv[2], sys.argv[3:]
rows = [r for f in files for r in json.load(open(f))["rows"]]
def mean(key):
    values = [r[key] for r in rows if r[key] is not None]
    return sum(values) / len(values) if values else float("nan")
succ = sum(r["succ"] for r in rows) / len(rows)
print("%s,%s,%d,%.1f,%.1f,%.1f,%.0f,%.0f" % (
    variant, test, len(rows), 100 * succ, mean("e2d_px"), mean("eo2d_px"),
    mean("e3d_root_mm"), mean("e3d_pa_mm")))
PY
}

run none "1"
run moved "1 2 3 4 5" --object-start-square 1
run push300 "1 2 3 4 5" --push 300
run both "1 2 3 4 5" --object-start-square 1 --push 300
