#!/usr/bin/env python3
"""Paired comparison of two walk-family measures (measure.sh, DRAWS=N) on
the same streams: held per tracker, per group, held by one alone, and the
two-sided sign test on the discordant streams.
  docs/experiments/walks2d_rd/paired.py PREFIX_A PREFIX_B DRAWS [FIRST_DRAW]
(FIRST_DRAW as measure.sh's: 4 compares draws 4..4+DRAWS-1, seeds 37-.)
e.g. paired.py docs/experiments/walks2d_rd/push_46.1 docs/experiments/walks2d_rd/worst_avg47-61 4 4
"""
import math
import re
import sys

LINE = re.compile(r'azimuth (\d+) deg, generation \d+ \(seed (\d+)\), (\S+): (tracked to the end|lost)')


def held(prefix, draws, first):
  result = {}
  for d in range(first, first + draws):
    path = prefix + '_generated' + ('_%d' % d if d else '') + '.log'
    for m in LINE.finditer(open(path).read()):
      result[(m.group(1), m.group(2), m.group(3))] = m.group(4).startswith('tracked')
  return result


def group(motion):
  if re.search(r'long_walk[12]', motion): return 'walks 1-2'
  if 'long_walk3' in motion: return 'walk 3+m'
  return 'styles'


a, b, draws = sys.argv[1], sys.argv[2], int(sys.argv[3])
first = int(sys.argv[4]) if len(sys.argv) > 4 else 0
ha, hb = held(a, draws, first), held(b, draws, first)
assert ha.keys() == hb.keys(), 'the measures are not of the same streams'
for name, h in ((a, ha), (b, hb)):
  groups = {}
  for key, ok in h.items():
    g = groups.setdefault(group(key[2]), [0, 0])
    g[0] += ok; g[1] += 1
  print('%-50s %d/%d  %s' % (name, sum(h.values()), len(h),
        ', '.join('%s %d/%d' % (g, *groups[g]) for g in ('walks 1-2', 'walk 3+m', 'styles'))))
only_a = sum(ha[k] and not hb[k] for k in ha)
only_b = sum(hb[k] and not ha[k] for k in ha)
n = only_a + only_b
p = min(1.0, 2 * sum(math.comb(n, i) for i in range(0, min(only_a, only_b) + 1)) / 2 ** n) if n else 1.0
print('held by the first alone %d, by the second alone %d; sign test p = %.2g' % (only_a, only_b, p))
