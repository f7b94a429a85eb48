# cut.py IN OUT START N: frames [START, START+N) of a bundle (truth or 2D)
import json, sys
src, dst, start, n = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
b = json.load(open(src))
sl = slice(start, start + n)
for v in b['views']:
    if 'cameras' in v and len(v['cameras']) > 1: v['cameras'] = v['cameras'][sl]
    v['clip']['keypoints'] = v['clip']['keypoints'][sl]
    if v['clip'].get('objects'):
        for o in v['clip']['objects']:
            for k, x in o.items():
                if isinstance(x, list) and len(x) > n: o[k] = x[sl]
b.pop('estimate', None)
if 'ground_truth' in b:
    for k in ('keypoints_m', 'poses'): b['ground_truth'][k] = b['ground_truth'][k][sl]
json.dump(b, open(dst, 'w'))
