/* sim/sweep/sweep.h -- `sfsim sweep` and `sfsim merge`: runs of one scene over many machine configs.
 *
 * Owns: sweep files (the INI files in configs/sweeps: lists, ranges, cross products or explicit points),
 * the sweep folder (manifest, one folder per point, done/failed markers), running points in
 * parallel as child `sfsim run` processes, resuming, sweep.csv, the gnuplot plots, and the
 * Slurm / GNU parallel scripts. Must not: simulate (each point is an `sfsim run`).
 * docs/sweep.md is the user's reference; the files of sim/sweep/ each hold one of these jobs
 * (sweep_int.h lists them).
 */
#ifndef SFSIM_SWEEP_H
#define SFSIM_SWEEP_H

#include <stdio.h>

/* The commands; argv excludes "sfsim sweep" / "sfsim merge". They return the EXIT_* codes of
 * sim/exitcodes.h: OK, INPUT, USAGE, IO (an output not written, the folder in use), POINTS (a
 * point failed or is unfinished), SIGNAL + the signal. */
int sweep_main(int argc, char **argv);
int merge_main(int argc, char **argv);
void sweep_usage(FILE *out);
void merge_usage(FILE *out);

#endif
