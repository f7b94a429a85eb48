#!/usr/bin/env python3
"""How each lost stream of a measure was lost, from generate --frames CSVs
(docs/experiments/walks2d_pd/measure.sh writes OUT_frames[_d].csv): the
keypoint that passed 100 px, for how many frames the worst keypoint had been
at 50 px or more before (a ramp, not a jump), the mean keypoint error then,
and the largest one-frame change of the worst error over the last 30 frames.
  docs/experiments/walks2d_rd/losses.py runs/measure/X_frames.csv runs/measure/X_frames_1.csv
"""
import csv
import sys
from collections import defaultdict
for f in sys.argv[1:]:
  rows=defaultdict(list)
  for r in csv.DictReader(open(f)): rows[(r['stream'],r['label'])].append(r)
  for (s,label),rs in rows.items():
    end=rs[-1]['end']
    if end!='early_exit': continue
    w=[float(x['worst_px']) for x in rs]; m=[float(x['mean_px']) for x in rs]
    # frames since worst last below 50
    k=len(w)-1
    while k>0 and w[k]>=50: k-=1
    jumps=max(abs(w[i]-w[i-1]) for i in range(max(1,len(w)-30),len(w)))
    print('%-60s lost@%4d kp=%-15s ramp(>=50px) %3d fr, mean at end %.0f px, max step %.0f px' % (label[:60], len(rs), rs[-1]['worst_keypoint'], len(w)-1-k, m[-1], jumps))
