#!/usr/bin/env bash
# Regenerates the seed corpora in fuzz/corpus/ (committed; rerun only when a
# format changes). Small valid inputs of every reader, made by our own
# commands from the repository's assets, so that the fuzzer starts from
# files that parse and mutates them into ones that almost do.
# Needs build/mimic2d (./setup.sh --no-demo) and python3.
set -euo pipefail
cd "$(dirname "$0")/.."
m2d=build/mimic2d
out=fuzz/corpus
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
rm -rf "$out"
mkdir -p "$out"/{clip_json,openpose,bundle,deepmimic,bvh,config,checkpoint}

# DeepMimic: the walk's first 4 frames.
python3 - assets/motions/deepmimic/humanoid3d_walk.txt "$out/deepmimic/walk4.txt" <<'PY'
import json, sys
motion = json.load(open(sys.argv[1]))
motion["Frames"] = motion["Frames"][:4]
json.dump(motion, open(sys.argv[2], "w"))
PY

# Bundles of those frames: with truth, stripped, and fitted (an estimate).
"$m2d" clip from-motion "$out/deepmimic/walk4.txt" --views 2 --fps 30 \
  -o "$out/bundle/truth.json" > /dev/null
"$m2d" clip strip "$out/bundle/truth.json" -o "$out/bundle/stripped.json" > /dev/null
"$m2d" clip from-motion assets/motions/deepmimic/humanoid3d_walk.txt --views 1 \
  --duration 0.5 -o "$work/walk05.json" > /dev/null
"$m2d" clip strip "$work/walk05.json" -o "$work/walk05_2d.json" > /dev/null
"$m2d" fit "$work/walk05_2d.json" -o "$out/bundle/fitted.json" --focal 1000 > /dev/null

# Clips: our format (a bundle's view) and COCO detector output of it.
python3 - "$out/bundle/stripped.json" "$out/clip_json" "$out/openpose" <<'PY'
import json, sys
bundle = json.load(open(sys.argv[1]))
clip = bundle["views"][0]["clip"]
json.dump(clip, open(sys.argv[2] + "/clip.json", "w"))
coco = []
for frame, points in enumerate(clip["keypoints"]):
    flat = [v for p in points for v in p]
    coco.append({"image_id": frame, "keypoints": flat, "score": 0.9})
json.dump(coco, open(sys.argv[2] + "/coco.json", "w"))
# OpenPose BODY_25: COCO-17 points at their BODY_25 slots, frames split by
# "----" lines (see openpose_fuzzer.cc).
body25_of_coco = [0, 16, 15, 18, 17, 5, 2, 6, 3, 7, 4, 12, 9, 13, 10, 14, 11]
frames = []
for points in clip["keypoints"]:
    body = [0.0] * 75
    for coco_index, slot in enumerate(body25_of_coco):
        body[3 * slot:3 * slot + 3] = points[coco_index]
    frames.append(json.dumps({"version": 1.3, "people": [
        {"person_id": [-1], "pose_keypoints_2d": body}]}))
open(sys.argv[3] + "/body25.json", "w").write("\n----\n".join(frames))
PY

# BVH: a 3-joint chain, 3 frames.
cat > "$out/bvh/chain.bvh" <<'BVH'
HIERARCHY
ROOT Hips
{
  OFFSET 0.0 0.0 0.0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0.0 5.0 0.0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0.0 5.0 0.0
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0.0 17.0 0.0 0.0 0.0 0.0 0.0 0.0 0.0
0.5 17.0 0.0 5.0 0.0 0.0 10.0 0.0 0.0
1.0 17.0 0.0 10.0 0.0 0.0 20.0 0.0 0.0
BVH

# Configs: a training config as checkpoints embed it, and fit options.
cp assets/policies/walk2d/config.yaml "$out/config/walk2d_embedded.yaml"
cat > "$out/config/fit.yaml" <<'YAML'
camera_motion: moving
focal_px: 1000
max_iterations: 50
YAML

# Checkpoint: a tiny network trained for one iteration on the 2-view bundle.
cat > "$work/tiny.yaml" <<YAML
data:
  bundles: [$PWD/$out/bundle/truth.json]
model:
  encoder_hidden: [8]
  encoder_features: 4
  policy_hidden: [8]
  critic_hidden: [8]
agent:
  num_envs: 4
  steps_per_env: 8
  minibatch_size: 16
run:
  run_dir: $work/run
  env_threads: 1
YAML
"$m2d" train "$work/tiny.yaml" --iterations 1 > "$work/train.log" 2>&1 || { cat "$work/train.log"; exit 1; }
cp "$work/run/checkpoint.pt" "$out/checkpoint/tiny.pt"
du -sh "$out"/*
