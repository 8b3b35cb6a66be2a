/* host/infile.h -- the one check every user's input file passes before it is read.
 *
 * Owns: what a tool accepts as an input file: a regular file (a symbolic link to one is followed),
 * no larger than the cap its caller gives. A folder, a character or block device (/dev/zero), a
 * FIFO or a socket is refused by name with the reason before a byte is read, so no input can hang
 * a tool or fill its memory. Opening uses O_NONBLOCK, so that a FIFO does not wait for a writer.
 * Must not: know any file format, print, or exit.
 *
 * Errors: -1 with "PATH: reason" in err, PATH as the user gave it:
 *   "PATH: cannot open: No such file or directory"
 *   "PATH: is a directory, not a regular file"
 *   "PATH: not a regular file (a character device)"
 *   "PATH: larger than 16 MiB, the most WHAT may hold"
 */
#ifndef SFSIM_HOST_INFILE_H
#define SFSIM_HOST_INFILE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Reads the regular file at path whole into a new buffer (NUL-terminated one byte past *len, which
 * the caller frees). max_bytes caps its size; what names the kind of file in the message when it is
 * larger ("an INI file", "a ray file"). 0 or -1. */
int infile_read(const char *path, uint64_t max_bytes, const char *what, char **buf, size_t *len, char *err,
                size_t errlen);

/* Opens the regular file at path for reading (O_RDONLY | O_CLOEXEC, blocking reads) after the
 * same checks, for a reader that streams it; the file's size in *size. The fd, or -1. */
int infile_open(const char *path, uint64_t max_bytes, const char *what, uint64_t *size, char *err, size_t errlen);

/* The same checks by name only, for a library that opens the file itself (OpenImageIO, tinygltf,
 * tinyobjloader): 0 when path names a regular file within max_bytes (0: no cap), or -1. */
int infile_check(const char *path, uint64_t max_bytes, const char *what, char *err, size_t errlen);

/* The reason in a message of this module, past its "PATH: " (for a caller that names the file its
 * own way, as the assembler's "FILE:1:1: cannot read file: REASON"). */
const char *infile_reason(const char *err, const char *path);

/* The length of a UTF-8 byte-order mark at the start of text (3), or 0. Text inputs skip it, as
 * the INI reader does. */
size_t infile_bom(const void *text, size_t len);

#ifdef __cplusplus
}
#endif

#endif
