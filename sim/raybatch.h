/* sim/raybatch.h -- ray batches for `sfsim trace`: reading ray files (text or binary) and
 * writing hit files.
 *
 * Owns: the file formats of docs/trace.md and every message about a malformed file.
 * Must not: trace anything.
 */
#ifndef SFSIM_RAYBATCH_H
#define SFSIM_RAYBATCH_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#define RAYBATCH_MAGIC "SFRAYS1"      /* 8 bytes with the terminating 0 */
#define RAYBATCH_MAX_RAYS (1u << 26)  /* 67M rays: a limit on what one file may claim */

typedef enum RayQuery { RAY_CLOSEST = 0, RAY_ANY = 1 } RayQuery;

typedef struct BatchRay {
    float org[3], dir[3];
    float tmax;            /* hits need 0 < t < tmax (infinity allowed) */
    uint32_t query;        /* RayQuery */
} BatchRay;

typedef struct BatchHit {
    uint32_t prim;         /* closest: primitive index or UINT32_MAX (miss); any: 1 occluded, 0 not */
    float t, u, v;         /* closest hits only */
    uint32_t invalid;      /* 1: the ray had a non-finite or zero direction or origin: not traced */
} BatchHit;

typedef struct RayBatch {
    BatchRay *rays;
    uint32_t count;
} RayBatch;

/* Parse a ray file held in memory (name for messages). Binary if it starts with the magic, else
 * text. 0, or -1 with "name:line: message" (text) / "name: byte N: message" (binary). */
int raybatch_parse(const char *name, const unsigned char *data, size_t len, RayBatch *out, char *err,
                   size_t errlen);
/* Read and parse a file. */
int raybatch_load(const char *path, RayBatch *out, char *err, size_t errlen);
void raybatch_free(RayBatch *b);

/* Write hits: text (one line per ray) or binary ("SFHITS1" format), whole or not at all
 * (host/outfile.h). 0 or -1 with a message naming path and the reason. */
int raybatch_write_hits(const char *path, const RayBatch *b, const BatchHit *hits, int binary, char *err,
                        size_t errlen);
/* A ray that cannot be traced: a non-finite origin or direction, or a zero direction. */
int raybatch_ray_invalid(const BatchRay *r);

#endif
