/* sim/provenance.h -- what made a run: the sfsim version and commit, the command line as typed
 * (quoted so that it pastes back into a shell), the folder it ran in, when it started and on which
 * host (issue 39, item 5; gem5 writes the same beside its statistics). docs/report.md, "run".
 *
 * Owns: those facts, recorded once by main() (prov_set_command) and read by the reports.
 * Must not: parse options (main.c does), or decide where the facts are written (sim/report.c).
 * A program that uses the library without sfsim's main() (the unit tests, tools/validation) has
 * no command line: prov_argc() is 0, prov_command() "", and the date is that of the first read.
 */
#ifndef SFSIM_PROVENANCE_H
#define SFSIM_PROVENANCE_H

#include <stddef.h>

struct cJSON;

/* Record argv (copied: option parsing may reorder or rewrite it), the working folder and the start
 * time. Called once, first thing in main(); a later call replaces the record. */
void prov_set_command(int argc, char **argv);

int prov_argc(void);
const char *prov_argv(int i);      /* "" when i is out of range */
/* The command line, each argument quoted for a POSIX shell where it needs it ("" when none). */
const char *prov_command(void);
const char *prov_cwd(void);        /* "" when it could not be read */
/* When the command started: ISO 8601 in local time with its offset, "2026-12-06T14:03:12+01:00". */
const char *prov_date(void);
const char *prov_host(void);       /* the host name; "" when it could not be read */

/* arg quoted for a POSIX shell into buf: as it is when every byte is safe (letters, digits and
 * "_@%+=:,./-"), else in single quotes with each ' written '\''; '' for "". The length the
 * quoted text needs (as snprintf: buf holds a truncated copy when that is len or more). */
size_t prov_quote(const char *arg, char *buf, size_t len);

/* Add version, commit, command, argv, cwd, date and host to o (report.json's "run" object).
 * 0, or -1 when out of memory. */
int prov_json(struct cJSON *o);

#endif
