/* sim/cli/help.c -- what `sfsim help COMMAND` and `sfsim COMMAND --help` print: every command's
 * usage, options and examples (sweep and merge print theirs from sim/sweep/sweep.c).
 *
 * Owns: the help texts. Must not: parse options (each command's table is in sim/main.c,
 * sim/cli/runopts.c and sim/cli/exec.c) or name internal labels (issue numbers, "seed 000"):
 * users read this.
 */
#include "help.h"

#include "../exithelp.h"

void help_commands(FILE *out)
{
    fprintf(out,
            "usage: sfsim <command> [options]\n"
            "\n"
            "sfsim simulates a stream-filtering ray tracing processor (Gribble & Ramani 2008).\n"
            "\n"
            "commands:\n"
            "  run      render a scene: --mode detailed (default: the kernel on the timed machine),\n"
            "           sampled (a sample of the work timed: cycles and fps with 95%% intervals),\n"
            "           functional (the kernel, no timing) or reference (the golden model)\n"
            "  exec     run an assembled program (.sfo) on the functional core; print registers\n"
            "           and counters\n"
            "  config   list the machine-config keys (--dump) or write their reference (--markdown)\n"
            "  compare  compare two images: RMSE, PSNR, largest difference, NaN/Inf counts\n"
            "  trace    closest-hit / any-hit queries for a file of rays, through the kernel or the golden model\n"
            "  sweep    run a scene over many machine configs in parallel (sweep files, resumable; CSV, plots)\n"
            "  merge    build a sweep's CSV and plots from its point folders (after Slurm or GNU parallel)\n"
            "  mem      replay a memory-access trace through the DRAM model: bandwidth, latency, row buffer\n"
            "  help     help on a command (sfsim help exec), or on the exit codes (sfsim help exit-codes)\n"
            "\n"
            "options everywhere: --help, --version. Options take their value as --set KEY=V, --set=KEY=V,\n"
            "-j 2 or -j2, and may come before or after the operands.\n"
            "\n"
            "examples:\n"
            "  sfsim run -o out                            the shipped Cornell box on the paper's machine\n"
            "  sfsim run --mode sampled --set core.simd_width=8 -o n8\n"
            "  sfsim sweep --sweep configs/sweeps/width.ini -o sweep -j2\n"
            "  sfsim help run                              every option of a command, with examples\n"
            "\n"
            "exit codes (every command; docs/exit-codes.md):\n");
    exithelp_print(out);
    fprintf(out, "\ndocumentation: docs/README.md\n");
}

void help_help(FILE *out)
{
    fprintf(out,
            "usage: sfsim help [COMMAND | exit-codes]\n"
            "\n"
            "Prints the help of COMMAND (run, exec, config, compare, trace, sweep, merge, mem, help), the exit\n"
            "codes every command returns (exit-codes), or without an argument the list of commands.\n"
            "`sfsim COMMAND --help` prints the same as `sfsim help COMMAND`.\n"
            "\n"
            "examples:\n"
            "  sfsim help run\n"
            "  sfsim help exit-codes\n");
}

void help_exit_codes(FILE *out)
{
    fprintf(out,
            "Exit codes of every sfsim and sfasm command (sim/exitcodes.def; docs/exit-codes.md):\n"
            "\n");
    exithelp_print(out);
}

void help_exec(FILE *out)
{
    fprintf(out,
            "usage: sfsim exec PROG.sfo [options]\n"
            "\n"
            "Runs an object produced by sfasm on the functional core until halt, a trap, or the\n"
            "instruction limit, then prints the scalar registers, the non-zero vector lanes, the\n"
            "masks and the counters per stage (instructions, operations by category, SIMD\n"
            "utilization = active lanes / (N x vector instructions)). With --timing the timing model\n"
            "runs beside it and the cycles are printed too: total, busy, stalls by cause, per stage,\n"
            "and the units' counters (docs/model.md).\n"
            "\n"
            "options:\n"
            "  -c, --config FILE        machine config (default: the built-in streamray machine)\n"
            "  --set SECTION.KEY=VALUE  override a config key (repeatable)\n"
            "  --width N                SIMD width, same as --set core.simd_width=N\n"
            "  --max-instructions N     instruction limit, same as --set sim.max_instructions=N\n"
            "  --dump-mem MEM:ADDR:WORDS  print WORDS words of MEM (rb0 rb1 idm spad scene fb) from\n"
            "                           byte address ADDR (a multiple of 4) after the run (repeatable)\n"
            "  -t, --timing             time the run on the machine of the config (detailed mode)\n"
            "  -q, --quiet              print only the summary line (and the timing, with --timing)\n"
            "  --no-progress            no progress line: a run still going after 2 s otherwise says on\n"
            "                           stderr, every 5 s, how many instructions it ran of the limit\n"
            "  --timeline FILE          (implies --timing) a pipeline trace in the Chrome trace event\n"
            "                           format (Perfetto, chrome://tracing): each instruction from issue\n"
            "                           to its results with its stall cycles and cause, and the cycles\n"
            "                           busy or stalled and why (docs/timeline.md)\n"
            "  --timeline-window FROM:TO  the cycles it holds (default 0:1000000; FROM: = 1000000 from FROM)\n"
            "\n"
            "The --dump-mem specs are checked against the config's memory sizes before the program runs.\n"
            "Exit codes: 0 halted, 1 bad input (config, object, --dump-mem spec), 2 usage, 3 trap or the\n"
            "instruction limit, 4 the timeline could not be written (sfsim help exit-codes).\n"
            "\n"
            "examples:\n"
            "  sfasm prog.s -o prog.sfo && sfsim exec prog.sfo\n"
            "  sfsim exec prog.sfo --timing --width 8           cycles and stalls on an 8-lane machine\n"
            "  sfsim exec prog.sfo --dump-mem spad:0:16 -q      16 words of the scratchpad after the run\n"
            "  sfsim exec prog.sfo --timeline pipe.json -q      open pipe.json in https://ui.perfetto.dev\n");
}

void help_config(FILE *out)
{
    fprintf(out,
            "usage: sfsim config (--dump | --markdown) [-c FILE] [--set SECTION.KEY=VALUE]...\n"
            "\n"
            "  --dump       every key with its value, type, default, range and help\n"
            "  --markdown   the key reference as Markdown (docs/config.md is this output)\n"
            "\n"
            "examples:\n"
            "  sfsim config --dump                                  the built-in machine\n"
            "  sfsim config --dump -c configs/streamray.ini --set core.simd_width=8\n");
}

void help_run(FILE *out)
{
    fprintf(out,
            "usage: sfsim run [-s SCENE] [-o DIR] [-c CONFIG] [--mode detailed|sampled|functional|reference] [options]\n"
            "\n"
            "Renders SCENE (a .gltf/.glb or .obj file, or a scene.ini) and writes DIR/frame.exr (linear),\n"
            "DIR/frame.png (tone-mapped sRGB), DIR/report.json, DIR/report.txt and DIR/stats.txt (every\n"
            "statistic, one per line, as gem5 writes them), and in detailed and sampled mode DIR/cost.png\n"
            "(simulated cycles per pixel, per tile; sampled: estimated). docs/report.md lists the fields.\n"
            "\n"
            "modes:\n"
            "  detailed    (default) the path-tracing kernel (kernels/pathtrace.s) on the functional core\n"
            "              with the cycle-accurate timing model of the machine in CONFIG: cycles, fps,\n"
            "              stalls by cause, per stage, generation and tile, the units' counters\n"
            "              (docs/model.md); the same image bits as functional mode\n"
            "  sampled     the golden model renders the image (the same bits) and counts every (tile, pass)\n"
            "              unit's work; a seeded random sample of the units runs on the timed kernel and the\n"
            "              rest are skipped; cycles, instructions and fps estimated with 95%% confidence\n"
            "              intervals (docs/sampling.md): by default until the cycles are known to +-1%%;\n"
            "              on a chip (chip.cores > 1 or chip.memory = shared) the makespan, from its\n"
            "              opening in full, units alone on warmed levels and waves of the whole chip\n"
            "  functional  the kernel executed instruction by instruction, no timing (fastest\n"
            "              simulation): operation mix, SIMD utilization and stream lengths per stage\n"
            "  reference   the golden model: a plain C path tracer over the packed scene memory\n"
            "\n"
            "options:\n"
            "  -s, --scene FILE         scene (default: the shipped Cornell box, scenes/cornell/scene.ini\n"
            "                           in sfsim's data folder, found beside the binary: docs/install.md)\n"
            "  -o, --out DIR            output folder (default: out): checked before any work, made when the\n"
            "                           outputs are written, each file whole or not at all (exit 4 if not;\n"
            "                           docs/report.md)\n"
            "  -c, --config FILE        machine config (stream.rays sets the tile: sqrt(M) pixels)\n"
            "  --set SECTION.KEY=VALUE  override a config key, or render.width, render.height,\n"
            "                           render.spp, render.max_depth, render.seed\n"
            "  -j, --threads N          host threads (default: all cores; results do not change)\n"
            "  --exposure X             scale before tone mapping frame.png (default 1)\n"
            "  --no-progress            no progress bar (it is shown only on a terminal anyway)\n"
            "  --target-error E         sampled mode: time units until the 95%% interval of the cycles is\n"
            "                           within +-E (a fraction: 0.01 = 1%%, the default), or every unit;\n"
            "                           on a chip, of the units' total: a makespan interval that came\n"
            "                           out wider is warned about\n"
            "  --sample F               sampled mode: time a fixed fraction F of the units, (0, 1], instead\n"
            "  --sample-seed S          sampled mode: which units (default 1)\n"
            "  --no-image               sampled mode: no image; the golden model runs only a pilot pass per\n"
            "                           tile for the units' counts (the estimate alone, fastest); on a chip\n"
            "                           with shared memory above 8 spp, no memory figures (docs/sampling.md)\n"
            "  --kernel FILE            kernel modes: the kernel source (default:\n"
            "                           kernels/pathtrace.s in the data folder, or $SFSIM_KERNEL)\n"
            "  --mem-trace FILE         detailed mode: every line the scene caches ask of the memory below\n"
            "                           them (misses, write-backs), in sfsim's trace format with the core\n"
            "                           as source, for `sfsim mem --trace FILE` (docs/chip.md)\n"
            "  --timeline FILE          detailed mode: what each core, unit and memory level did, cycle by\n"
            "                           cycle (busy, stalled and why, idle; requests in flight), in the\n"
            "                           Chrome trace event format for Perfetto or chrome://tracing\n"
            "                           (docs/timeline.md); the memo of blocks is off while it records\n"
            "  --timeline-window FROM:TO  the cycles the timeline holds (default 0:1000000; FROM: for\n"
            "                           1000000 cycles from FROM; 0:18446744073709551615 for all)\n"
            "\n"
            "examples:\n"
            "  sfsim run -o out                                        the Cornell box, detailed mode\n"
            "  sfsim run -s scene.gltf --set render.spp=4 --set=core.simd_width=8 -j2 -o n8\n"
            "  sfsim run --mode sampled --target-error 0.005 -o samp   cycles and fps to +-0.5%% (95%%)\n"
            "  sfsim run --mode reference -o ref && sfsim compare ref/frame.exr out/frame.exr\n"
            "  sfsim run -c configs/chip16-ddr4.ini -s scenes/conference/scene.ini -o chip   16 cores, L2, DDR4\n"
            "  sfsim run --mem-trace out.trc -o out && sfsim mem --trace out.trc   its misses through DRAM\n"
            "  sfsim run -c configs/chip16-ddr4.ini --timeline tl.json --timeline-window 200000:300000 -o c\n");
}

void help_compare(FILE *out)
{
    fprintf(out,
            "usage: sfsim compare A B [--max-rmse X] [--min-psnr DB] [--max-diff X]\n"
            "\n"
            "Compares two images of the same size (any format OpenImageIO reads; EXR compares linear\n"
            "radiance, PNG the stored 0..1 values) and prints RMSE, PSNR (peak 1), the largest channel\n"
            "difference, both means and the NaN/Inf counts. The values are compared as stored, never\n"
            "converted: a linear image (EXR, HDR, PFM) against a display image (PNG, JPEG) gets a warning\n"
            "on stderr, since PNG's values are sRGB-encoded, exposure-scaled and clamped.\n"
            "\n"
            "thresholds, for scripts (each optional; the figures are printed either way):\n"
            "  --max-rmse X     exit 6 when the RMSE is above X\n"
            "  --min-psnr DB    exit 6 when the PSNR is below DB decibels\n"
            "  --max-diff X     exit 6 when the largest channel difference is above X\n"
            "  Images with different counts of NaN or Inf values fail every threshold.\n"
            "\n"
            "Exit 0 when it compared (and every threshold given held), 1 when an image cannot be read or the\n"
            "sizes differ, 4 when sfsim's image library does not load, 6 when a threshold was exceeded (the\n"
            "message says which).\n"
            "\n"
            "examples:\n"
            "  sfsim compare ref/frame.exr out/frame.exr\n"
            "  sfsim compare ref/frame.exr out/frame.exr --max-rmse 1e-3 || echo \"images differ\"\n");
}

void help_trace(FILE *out)
{
    fprintf(out,
            "usage: sfsim trace -s SCENE --rays FILE -o HITS [options]\n"
            "\n"
            "Traces each ray of FILE (text or binary, docs/trace.md) against SCENE and writes its closest hit\n"
            "(distance, primitive, barycentrics) or miss, or for any-hit rays whether it is occluded, to HITS.\n"
            "\n"
            "options:\n"
            "  --mode functional|detailed|reference  the kernel's traversal and intersection on the\n"
            "                           functional core (default), the same timed on the machine of the\n"
            "                           config (prints cycles and stalls by cause), or the golden model's\n"
            "  -c, --config FILE        machine config; --set SECTION.KEY=VALUE overrides a key\n"
            "  --binary                 write HITS in the binary format (default: text)\n"
            "  -j, --threads N          host threads (default: all cores; results do not change)\n"
            "  --kernel FILE            the kernel source (default: kernels/pathtrace.s beside the binary)\n"
            "\n"
            "examples (a ray per line: origin, direction, and optionally tmax and any; docs/trace.md):\n"
            "  printf '278 273 -800  0 0 1\\n' > rays.txt\n"
            "  sfsim trace -s scenes/cornell/scene.ini --rays rays.txt -o hits.txt\n"
            "  sfsim trace -s scene.gltf --rays rays.bin --mode detailed -j2 -o hits.txt\n");
}

void help_mem(FILE *out)
{
    fprintf(out,
            "usage: sfsim mem --trace FILE [-c CONFIG] [--set dram.KEY=VALUE]... [--format dramsim3|sfsim|auto]\n"
            "                 [--mapping ORDER] [-o DIR] [--json]\n"
            "\n"
            "Replays a memory-access trace through the DRAM of the config (the [dram] keys: a preset such as\n"
            "ddr4_2400, ddr5_4800, lpddr5_6400, gddr6_14000 or hbm2_2000, and overrides; docs/dram.md) and\n"
            "prints per channel and in total: requests, bandwidth in GB/s and its share of the peak, average\n"
            "and p50/p95/p99 latency (DRAM cycles and ns), row-buffer hits/misses/conflicts, average and\n"
            "largest queue occupancy, refreshes, and back-pressure (requests that waited for a queue slot).\n"
            "\n"
            "trace formats (docs/dram.md):\n"
            "  dramsim3   DRAMsim3's text trace: '0xADDR READ|WRITE CYCLE' a line, CYCLE in DRAM clocks\n"
            "  sfsim      a header 'sfsim-memtrace 1 clock_mhz=F', then 'CYCLE R|W 0xADDR [SOURCE]' a line,\n"
            "             CYCLE in the header's clock (converted exactly: floor(CYCLE x DRAM MHz / F))\n"
            "  auto       (default) sfsim when the first line is its header, else dramsim3\n"
            "Cycles never decrease; '#' comment lines and blank lines are skipped.\n"
            "\n"
            "options:\n"
            "  --trace FILE             the trace (required)\n"
            "  -c, --config FILE        machine config; --set SECTION.KEY=VALUE overrides a key\n"
            "  --format F               dramsim3, sfsim or auto (see above)\n"
            "  --mapping ORDER          address mapping, any order of ch,ra,bg,ba,ro,co (most significant\n"
            "                           first), beyond the orders the key dram.mapping offers\n"
            "  -o, --out DIR            also write DIR/report.txt and DIR/report.json (each whole or not at all)\n"
            "  --json                   print the JSON report instead of the text one\n"
            "\n"
            "Exit codes: 0 replayed, 1 bad input (the trace: the message names file and line; a config\n"
            "key), 2 usage, 4 an output could not be written (sfsim help exit-codes).\n"
            "\n"
            "examples:\n"
            "  printf '0x0 READ 0\\n0x40 READ 0\\n0x80 WRITE 10\\n' > t.trc\n"
            "  sfsim mem --trace t.trc                                   DDR4-2400, one channel\n"
            "  sfsim mem --trace t.trc --set dram.preset=hbm2_2000 --set dram.page_policy=closed\n"
            "  sfsim mem --trace run.mtr --mapping ro,ba,bg,ra,co,ch -o memrep --json\n");
}
