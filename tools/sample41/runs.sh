#!/bin/sh
# tools/sample41/runs.sh OUT -- the detailed runs of issue 41's design study (docs/sampling.md,
# "Sampling a chip (issue 41): the design, measured"). The conference room, 32 x 32 tiles
# (stream.rays = 1024), one host thread each. About 20 minutes of the 2 host cores in all (2026-12-07).
set -e
out=${1:?usage: runs.sh OUT}
mkdir -p "$out"
run() { # NAME W H SPP [sfsim options...]
    n=$1; w=$2; h=$3; s=$4; shift 4
    bin/sfsim run --mode detailed -s scenes/conference/scene.ini --set stream.rays=1024 --set render.width=$w \
        --set render.height=$h --set render.spp=$s --no-progress -j1 "$@" -o "$out/$n"
}
c16=configs/chip16-ddr4.ini c64=configs/chip64-gddr6.ini
run paper4 256 256 4                                                  # the paper's machine: cold units, own bus
run buscold4 256 256 4 -c $c16 --set chip.memory=bus --set chip.cold_units=1
run buswarm4 256 256 4 -c $c16 --set chip.memory=bus --set chip.cold_units=0
run sharedcold4 256 256 4 -c $c16 --set chip.cold_units=1
run warm4 256 256 4 -c $c16                                           # the chip: warm, shared L2 and DDR4
run k1shared4 256 256 4 -c $c16 --set chip.cores=1                    # one core on the same L2 and DDR4
run paper1 256 256 1
run buswarm1 256 256 1 -c $c16 --set chip.memory=bus
run warm1 256 256 1 -c $c16
run k1shared1 256 256 1 -c $c16 --set chip.cores=1
run paper16 256 256 16
run warm16 256 256 16 -c $c16
run warm512x4 512 512 4 -c $c16
run stress16 256 256 4 -c $c16 --set l2.size_kb=256                   # an L2 the working set does not fit
run stress1 256 256 4 -c $c16 --set l2.size_kb=256 --set chip.cores=1
run g64 512 512 1 -c $c64
run g64k1 512 512 1 -c $c64 --set chip.cores=1
run warm1k 1024 1024 1 -c $c16                                       # 64 tiles a core: the paper frame's tiling
# the paper machine's per-unit cycles and the golden model's per-unit counts (units-conference.tsv)
make build/bench/speed_vs_error
build/bench/speed_vs_error --size 256x256x16 "$out/bench16"
build/bench/speed_vs_error --size 512x512x4 "$out/bench512x4"
build/bench/speed_vs_error --size 1024x1024x1 "$out/bench1k"
