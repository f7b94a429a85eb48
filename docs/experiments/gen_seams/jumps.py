#!/usr/bin/env python3
"""Jumps of generated 2D against the recorded 2D of the same motion (issue 16,
docs/generation.md 4b, "Seams"): per frame, the largest keypoint step from the
frame before (px); a jump is a step over 1.2x the fastest step of the motion's
recorded views. Prints, per setting and motion, jumps per minute, the 99th
percentile and the largest step, and where in the 16-frame decoding period
(emit_codes 4 x 4 frames) the jumps fall.

  # the recorded walks' 2D: TILT=rig scripts/make_walks.sh runs/walks_rig
  # the generated clips, per SETTING (e.g. seams as decoded, blended):
  #   build/mimic2d generate runs/gen_walks --seconds 60 --view 30,15,4.5 \
  #     --motion M --seed S [--lookahead 1 --blend-seams false] -o DIR/SETTING_mM_sS.json
  docs/experiments/gen_seams/jumps.py DIR runs/walks_rig
"""
import collections
import glob
import json
import math
import os
import sys

MOTIONS = ["long_walk1", "long_walk1_mirror", "long_walk2", "long_walk2_mirror",
           "long_walk3", "long_walk3_mirror", "long_zombie", "stealthy_walk0",
           "stealthy_walk1"]  # configs/gen/walks.yaml's data.motions


def steps(keypoints):
    return [max(math.hypot(a[0] - b[0], a[1] - b[1]) for a, b in zip(frame, before))
            for before, frame in zip(keypoints, keypoints[1:])]


def main(generated_dir, recorded_dir):
    recorded_max = {}
    for m, name in enumerate(MOTIONS):
        path = os.path.join(recorded_dir, name + "_2d.json")
        if os.path.exists(path):
            views = json.load(open(path))["views"]
            recorded_max[m] = max(max(steps(v["clip"]["keypoints"])) for v in views)
    table = collections.defaultdict(list)
    period = collections.defaultdict(collections.Counter)
    for path in sorted(glob.glob(os.path.join(generated_dir, "*_m*_s*.json"))):
        setting, motion, _ = os.path.basename(path)[:-5].rsplit("_", 2)
        m = int(motion[1:])
        if m not in recorded_max:
            continue
        s = steps(json.load(open(path))["keypoints"])
        jumps = [f + 1 for f, step in enumerate(s) if step > 1.2 * recorded_max[m]]
        period[setting].update(f % 16 for f in jumps)
        ordered = sorted(s)
        table[(setting, m)].append((len(jumps) / (len(s) / 30 / 60),
                                    ordered[int(0.99 * (len(s) - 1))], ordered[-1]))
    print("setting motion recorded_max_px jumps_per_min p99_px max_px")
    for (setting, m), rows in sorted(table.items()):
        n = len(rows)
        print("%s %s %.1f %.1f %.1f %.1f" % (
            setting, MOTIONS[m], recorded_max[m], sum(r[0] for r in rows) / n,
            sum(r[1] for r in rows) / n, max(r[2] for r in rows)))
    for setting, counter in sorted(period.items()):
        print(setting, "jumps by frame mod 16:", [counter[i] for i in range(16)])


if __name__ == "__main__":
    main(*sys.argv[1:3])
