/* host/version.h -- which sfsim this is: one version for sfsim and sfasm, and the commit built.
 *
 * Owns: the version string (the file VERSION at the top of the tree) and the commit the binaries
 * were built from (scripts/version.sh at build time; "unknown" outside a git checkout, with
 * "-dirty" when the tree had uncommitted changes). Must not: read anything at run time.
 */
#ifndef SFSIM_HOST_VERSION_H
#define SFSIM_HOST_VERSION_H

#ifdef __cplusplus
extern "C" {
#endif

/* "0.9.0" */
const char *version_string(void);
/* "155a89e02465", "155a89e02465-dirty" or "unknown" */
const char *version_commit(void);

#ifdef __cplusplus
}
#endif

#endif
