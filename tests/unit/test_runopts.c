/* tests/unit/test_runopts.c -- the one check of `sfsim run`'s and `sfsim trace`'s options
 * (sim/cli/runopts.c): the exit code of each kind of mistake, the settings a good command line
 * leaves in the options, and that the mode is checked against the machine the options build
 * before any work (no scene is opened: the scene path given does not exist). The messages
 * themselves are checked end to end by tests/cli/run.sh and tests/cli/cases/options.sh.
 */
#include <criterion/criterion.h>
#include <stdio.h>

#include "../../sim/cli/runopts.h"
#include "../../sim/exitcodes.h"

/* Every test runs in its own process (Criterion forks): the messages go nowhere. */
static void quiet(void) { cr_assert_not_null(freopen("/dev/null", "w", stderr)); }

#define ARGV(...) ((char *[]){__VA_ARGS__, NULL})
#define ARGC(...) ((int)(sizeof((char *[]){__VA_ARGS__}) / sizeof(char *)))
#define RUN(c, ...) runopts_run(ARGC("run", __VA_ARGS__), ARGV("run", __VA_ARGS__), c)
#define TRACE(c, ...) runopts_trace(ARGC("trace", __VA_ARGS__), ARGV("trace", __VA_ARGS__), c)

static int run_rc(int rc, RunCmd *c)
{
    cli_config_free(&c->ca);
    return rc;
}

Test(runopts, sampled_settings_without_sampled_mode_or_both_sizes_are_usage_errors, .init = quiet)
{
    RunCmd c;
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--sample", "0.1"), &c), EXIT_USAGE);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--target-error", "0.1", "--mode", "detailed"), &c), EXIT_USAGE);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--no-image", "--mode", "functional"), &c), EXIT_USAGE);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "sampled", "--sample", "0.1", "--target-error", "0.01"), &c),
                 EXIT_USAGE);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "extra"), &c), EXIT_USAGE);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--bogus"), &c), EXIT_USAGE);
}

Test(runopts, values_out_of_range_are_bad_input, .init = quiet)
{
    RunCmd c;
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "sampled", "--sample", "0"), &c), EXIT_INPUT);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "sampled", "--sample", "1.5"), &c), EXIT_INPUT);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "sampled", "--target-error", "1"), &c), EXIT_INPUT);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "Detailed"), &c), EXIT_INPUT);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "-j", "0"), &c), EXIT_INPUT);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--set", "render.spp=0"), &c), EXIT_INPUT);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--set", "stream.rays=2048"), &c), EXIT_INPUT);
}

/* The golden model has the path tracer and the Phong workload only: the reference and sampled
 * modes cannot run the others, and that is said before the scene is opened. */
Test(runopts, a_mode_the_machine_cannot_run_is_bad_input_before_any_work, .init = quiet)
{
    RunCmd c;
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "reference", "--set", "workload.kind=diffuse"), &c),
                 EXIT_INPUT);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "sampled", "--set", "workload.kind=specular"), &c),
                 EXIT_INPUT);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "detailed", "--set", "workload.kind=diffuse"), &c),
                 EXIT_OK);
    cr_expect_eq(run_rc(RUN(&c, "-s", "none.ini", "--mode", "reference", "--set", "workload.kind=phong"), &c),
                 EXIT_OK);
}

Test(runopts, a_good_command_line_leaves_checked_settings)
{
    RunCmd c;
    cr_assert_eq(RUN(&c, "-s", "none.ini", "--mode", "sampled", "--sample", "0.25", "--set", "render.spp=3", "-o", "d"),
                 EXIT_OK);
    cr_expect_eq(c.o.mode, RUN_SAMPLED);
    cr_expect_eq(c.o.sample, 0.25);
    cr_expect_eq(c.o.target_error, 0.0, "--sample is the fixed-size design: no target");
    cr_expect_eq(c.o.spp, 3);
    cr_expect_str_eq(c.o.out_dir, "d");
    cr_expect_eq(c.o.cfg, &c.cfg);
    cli_config_free(&c.ca);
    cr_assert_eq(RUN(&c, "-s", "none.ini"), EXIT_OK);
    cr_expect_eq(c.o.mode, RUN_DETAILED, "detailed by default");
    cr_expect_str_eq(c.o.out_dir, "out");
    cli_config_free(&c.ca);
}

Test(runopts, trace_options, .init = quiet)
{
    TraceCmd c;
    cr_expect_eq(TRACE(&c, "-s", "none.ini", "--rays", "r.txt", "-o", "h", "--mode", "sampled"), EXIT_INPUT);
    cli_config_free(&c.ca);
    cr_expect_eq(TRACE(&c, "-s", "none.ini", "-o", "h"), EXIT_USAGE);
    cli_config_free(&c.ca);
    cr_expect_eq(TRACE(&c, "-s", "none.ini", "--rays", "r.txt", "-o", "h", "--sample", "0.1"), EXIT_USAGE);
    cli_config_free(&c.ca);
    cr_assert_eq(TRACE(&c, "-s", "none.ini", "--rays", "r.txt", "-o", "h"), EXIT_OK);
    cr_expect_eq(c.o.mode, RUN_FUNCTIONAL, "functional by default");
    cr_expect_gt(c.o.threads, 0, "every core by default");
    cr_expect_eq(c.o.cfg, &c.cfg);
    cli_config_free(&c.ca);
}
