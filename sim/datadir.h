/* sim/datadir.h -- where sfsim's own files are: kernels, machine configs, the default scene.
 *
 * Found relative to the running binary, never to the working directory, so `sfsim` works from any
 * folder: in a build tree (bin/sfsim beside kernels/) and in an installed tree
 * (PREFIX/bin/sfsim beside PREFIX/share/sfsim/). docs/install.md describes the layout.
 */
#ifndef SFSIM_DATADIR_H
#define SFSIM_DATADIR_H

#include <stddef.h>

/* The folder holding kernels/pathtrace.s, configs/ and scenes/cornell/: $SFSIM_DATA_DIR if set,
 * else <binary's folder>/.. (build tree), else <binary's folder>/../share/sfsim (installed).
 * Returns buf, or NULL (with a message in err) when none of them holds the kernel. */
const char *datadir_get(char *buf, size_t len, char *err, size_t errlen);

/* <data dir>/rel into buf; on failure the message is in err and NULL is returned. */
const char *datadir_path(const char *rel, char *buf, size_t len, char *err, size_t errlen);

/* Relative paths of the shipped files, below the data dir. */
#define DATADIR_KERNEL "kernels/pathtrace.s"
#define DATADIR_DEFAULT_SCENE "scenes/cornell/scene.ini"
#define DATADIR_DEFAULT_CONFIG "configs/streamray.ini"

#endif
