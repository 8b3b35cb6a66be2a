#!/usr/bin/env python3
"""tools/sample41/l2replay.py -- a chip's DRAM traffic by (tile, pass) unit, from a detailed run.

Replays the requests below the L1s of `sfsim run --mode detailed --mem-trace TRACE -o DIR` (in the
order the trace has them) through a least-recently-used, write-back, write-allocate L2 of LINES
lines and WAYS ways (set = line number mod sets), and gives each request to the unit its core was
running then: a core's tiles run in frame order, each tile's passes one after another, their cycles
from report.json's tiles[].passes[].cycles. Prints, by pass, a unit's mean L2 misses and dirty
evictions (its DRAM reads and write-backs), and the totals to hold against report.json's
l2.misses and l2.writebacks (the real L2 has banks and miss-status registers; the replay does not).
docs/sampling.md, "Measured", fourth session, used it on the unit test's Cornell chip:

  bin/sfsim run --mode detailed -s scenes/cornell/scene.ini -c CHIP.ini --set render.width=256 \\
      --set render.height=256 --set render.spp=4 -j1 --mem-trace trace.txt -o det
  tools/sample41/l2replay.py det/report.json trace.txt 4096 16

(CHIP.ini: stream.rays 1024; chip.cores 16, cold_units 0, memory shared; scene.cache_kb 1;
l2.size_kb 256, l2.banks 4; noc.latency 4 -- tests/unit/test_chipsampled.c's chip.)
"""
import collections
import json
import sys


def main():
    if len(sys.argv) != 5:
        sys.exit("usage: l2replay.py REPORT.json TRACE LINES WAYS")
    rep = json.load(open(sys.argv[1]))
    lines, ways = int(sys.argv[3]), int(sys.argv[4])
    nsets = lines // ways
    spp = len(rep["tiles"][0]["passes"])
    spans = collections.defaultdict(list)  # core -> [(start, end, unit)]
    tiles_of = collections.defaultdict(list)
    for t, tile in enumerate(rep["tiles"]):
        tiles_of[tile["core"]].append(t)
    for core, tiles in tiles_of.items():
        at = 0
        for t in sorted(tiles):
            for p, ps in enumerate(rep["tiles"][t]["passes"]):
                spans[core].append((at, at + ps["cycles"], t * spp + p))
                at += ps["cycles"]
    where = {core: 0 for core in spans}

    def unit_of(core, cycle):  # the trace is in cycle order: each core's index only moves on
        s = spans[core]
        i = where[core]
        while i + 1 < len(s) and cycle >= s[i][1]:
            i += 1
        where[core] = i
        return s[i][2]

    sets = [collections.OrderedDict() for _ in range(nsets)]
    miss, wb, units = collections.Counter(), collections.Counter(), set()
    with open(sys.argv[2]) as f:
        for text in f:
            if text.startswith("sfsim-memtrace"):
                continue
            cycle, rw, addr, core = text.split()
            line, u = int(addr, 16) // 64, unit_of(int(core[4:]), int(cycle))
            units.add(u)
            s = sets[line % nsets]
            if line in s:
                s.move_to_end(line)
                s[line] = s[line] or rw == "W"
                continue
            if rw == "R":
                miss[u] += 1
            if len(s) >= ways and s.popitem(last=False)[1]:
                wb[u] += 1
            s[line] = rw == "W"
    print("replayed: %d misses, %d write-backs (the run: %s, %s)" % (
        sum(miss.values()), sum(wb.values()), rep["l2"]["misses"], rep["l2"]["writebacks"]))
    for p in range(spp):
        us = [u for u in units if u % spp == p]
        if us:
            print("pass %d: %d units, a unit's mean %.1f misses + %.1f write-backs" % (
                p, len(us), sum(miss[u] for u in us) / len(us), sum(wb[u] for u in us) / len(us)))


if __name__ == "__main__":
    main()
