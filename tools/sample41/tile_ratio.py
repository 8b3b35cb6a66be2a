#!/usr/bin/env python3
"""tools/sample41/tile_ratio.py -- issue 41's design study (docs/sampling.md, "Sampling a chip").

  tile_ratio.py schedule RUN...   replay the distributor on each run's tiles[].cycles (tiles in frame
                                  order to the earliest idle core, ties to the lowest) and compare
                                  with the report's makespan, tiles[].core and cores[].finish
  tile_ratio.py ratio A B [WAVE]  per-tile ratio of A's cycles to B's (same frame): mean, spread, the
                                  totals' ratio; with WAVE, the first WAVE tiles and the rest apart
  tile_ratio.py tiles UNITS.tsv SPP CHIP
                                  chiprep's TILES.txt: per tile, its paper-machine cycles (the sum
                                  of its units in bench/speed_vs_error's units-conference.tsv) and
                                  its cycles in CHIP's run
RUN, A, B, CHIP: output folders of `sfsim run --mode detailed` (report.json)."""
import json, statistics as st, sys

def load(d):
    return json.load(open(f'{d}/report.json'))

def list_schedule(cycles, K):
    free, core = [0] * K, []
    for c in cycles:
        k = min(range(K), key=lambda i: (free[i], i))
        core.append(k)
        free[k] += c
    return max(free), core, free

def schedule(d):
    r = load(d)
    K = r['chip']['cores'] if 'chip' in r else 1
    c = [t['cycles'] for t in r['tiles']]
    ms, core, free = list_schedule(c, K)
    same = sum(1 for t, k in zip(r['tiles'], core) if t.get('core', 0) == k)
    fin = all(free[k] == r['cores'][k]['finish'] for k in range(K)) if 'cores' in r else None
    print(f"{d}: K={K}, {len(c)} tiles, makespan {r['cycles']}, list schedule {ms} (difference {ms - r['cycles']}), "
          f"same core {same}/{len(c)}, finishes equal: {fin}; makespan / (sum of tiles / K) = {r['cycles'] / (sum(c) / K):.4f}")

def describe(label, q):
    m = st.mean(q)
    print(f"  {label}: {len(q)} tiles, mean {m:.4f}, sd {st.pstdev(q):.4f} (CV {100 * st.pstdev(q) / m:.2f} %), "
          f"min {min(q):.4f}, max {max(q):.4f}")

def ratio(a, b, wave=0):
    ca = [t['cycles'] for t in load(a)['tiles']]
    cb = [t['cycles'] for t in load(b)['tiles']]
    q = [x / y for x, y in zip(ca, cb)]
    print(f"{a} / {b}: totals {sum(ca) / sum(cb):.4f}")
    describe('per tile', q)
    if wave:
        describe(f'first {wave} tiles', q[:wave])
        describe('the rest', q[wave:])

def tiles(units, spp, chip):
    u = {}
    for line in open(units):
        if not line.startswith('#'):
            f = line.split()
            u[int(f[0])] = float(f[1])
    for t, tile in enumerate(load(chip)['tiles']):
        print('%d %d' % (sum(u[t * spp + q] for q in range(spp)), tile['cycles']))

if __name__ == '__main__':
    if len(sys.argv) >= 3 and sys.argv[1] == 'schedule':
        for d in sys.argv[2:]:
            schedule(d)
    elif len(sys.argv) in (4, 5) and sys.argv[1] == 'ratio':
        ratio(sys.argv[2], sys.argv[3], int(sys.argv[4]) if len(sys.argv) == 5 else 0)
    elif len(sys.argv) == 5 and sys.argv[1] == 'tiles':
        tiles(sys.argv[2], int(sys.argv[3]), sys.argv[4])
    else:
        sys.exit(__doc__)
