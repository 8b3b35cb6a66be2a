/* sim/sweep/emit.c -- `sfsim sweep --emit slurm|parallel`: the scripts that run a sweep's points
 * beyond this machine, as Slurm array tasks or GNU parallel commands (docs/sweep.md, "Beyond one
 * machine").
 *
 * Owns: the text of DIR/sweep.slurm and DIR/sweep.parallel (each task an `sfsim sweep ... --point
 * K` with the defining arguments, paths absolute) and the next steps it prints. Must not: run
 * anything, or write into the point folders.
 */
#include "../../host/outfile.h"
#include "sweep_int.h"

#include "../exitcodes.h"

/* `"sfsim" sweep <defining arguments> -o "DIR"`, paths absolute. */
static void task_command(UtilBuf *b, const char *exe, const SweepPlan *pl, const SweepArgs *a, const char *dir)
{
    sweep_shell_word(b, exe, 1);
    util_buf_puts(b, " sweep");
    if (pl->config) {
        util_buf_puts(b, " -c ");
        sweep_shell_word(b, pl->config, 1);
    }
    util_buf_puts(b, " --sweep ");
    sweep_shell_word(b, pl->sweep, 1);
    util_buf_puts(b, " -s ");
    sweep_shell_word(b, pl->scene, 1);
    util_buf_printf(b, " --mode %s", pl->mode);
    if (pl->sample) {
        util_buf_puts(b, " --sample ");
        sweep_shell_word(b, pl->sample, 1);
    }
    for (int i = 0; i < pl->nsets; i++) {
        util_buf_puts(b, " --set ");
        sweep_shell_word(b, pl->sets[i], 1);
    }
    util_buf_printf(b, " --threads-per-point %d%s -o ", a->threads, a->retry ? " --retry-failed" : "");
    sweep_shell_word(b, dir, 1);
}

/* DIR on the `#SBATCH --output=` line. Slurm expands that path as a filename pattern (%A, %a, %x,
 * %j, ...), so a '%' of the folder's own name is written "%%", or the tasks' logs would go to a
 * folder that does not exist and every task would fail before running. */
static void output_dir(UtilBuf *b, const char *dir)
{
    UtilBuf d = {0};
    for (const char *c = dir; *c; c++)
        util_buf_add(&d, *c == '%' ? "%%" : c, *c == '%' ? 2 : 1);
    sweep_shell_word(b, sweep_buf_text(&d), 0);
    util_buf_free(&d);
}

int sweep_emit_scripts(const SweepPlan *pl, const SweepArgs *a, const char *exe, const char *dir)
{
    char err[PATH_MAX + 256];
    UtilBuf b = {0};
    int slurm = !strcmp(a->emit, "slurm");
    char *path = xasprintf("%s/sweep.%s", dir, slurm ? "slurm" : "parallel");
    if (slurm) {
        util_buf_printf(&b, "#!/bin/bash\n#SBATCH --job-name=sfsim-sweep\n#SBATCH --array=0-%d\n"
                            "#SBATCH --cpus-per-task=%d\n", pl->npoints - 1, a->threads);
        util_buf_puts(&b, "#SBATCH --output=");
        output_dir(&b, dir);
        util_buf_puts(&b, "/points/slurm-%A_%a.out\n");
        util_buf_printf(&b, "# Written by sfsim sweep --emit slurm: one array task per point of the sweep in %s.\n"
                            "# A task whose point is done already exits at once; after the tasks: sfsim merge %s\n",
                   dir, dir);
        task_command(&b, exe, pl, a, dir);
        util_buf_puts(&b, " --point \"$SLURM_ARRAY_TASK_ID\"\n");
    } else {
        for (int k = 0; k < pl->npoints; k++) {
            task_command(&b, exe, pl, a, dir);
            util_buf_printf(&b, " --point %d\n", k);
        }
    }
    int rc = outfile_write_file(NULL, path, sweep_buf_text(&b), b.len, err, sizeof err);
    util_buf_free(&b);
    if (rc) {
        fprintf(stderr, "sfsim sweep: %s\n", err);
        free(path);
        return EXIT_IO;
    }
    if (slurm)
        printf("sweep: wrote %s, a Slurm array job of %d tasks, one per point (the folder must be on storage the "
               "nodes share). Next:\n  sbatch %s\n  sfsim merge %s      # when the tasks have ended: sweep.csv and "
               "plots\n", path, pl->npoints, path, dir);
    else
        printf("sweep: wrote %s, %d commands, one per point. Next:\n  parallel -j %d < %s\n"
               "      (or parallel -S host1,host2 ... with %s on storage the hosts share)\n"
               "  sfsim merge %s      # then: sweep.csv and plots\n", path, pl->npoints, a->jobs, path, dir, dir);
    free(path);
    return EXIT_OK;
}
