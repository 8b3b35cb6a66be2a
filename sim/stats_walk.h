/* sim/stats_walk.h -- inside the statistics module (sim/stats.c, stats_text.c, stats_csv.c): reading
 * a row's value, its elements and its report.json path, and the walk over the rows. Not for use
 * outside the module (the module's interface is sim/stats.h).
 */
#ifndef SFSIM_STATS_WALK_H
#define SFSIM_STATS_WALK_H

#include "stats.h"

/* A report.json path's segment: a key (literal, or text around one "{dim}"), or an array "[dim]". */
typedef struct Seg {
    int array;             /* "[dim]" */
    int dim;               /* the row's dimension it indexes (position in dims), or -1 */
    const char *pre, *post;
    int prelen, postlen;   /* the text around "{dim}" (pre alone for a literal key) */
} Seg;
#define MAX_SEGS 8


/* Elements of d in this run (generations reached, tiles rendered; the others: stats_dim_size). */
int stats_dim_len(const StatsCtx *c, StatsDim d);
/* The value of r's element idx; *na = 1 when it has no meaning. */
double stats_row_value(const StatsCtx *c, const StatsRow *r, const int *idx, int *na);
/* The number report.json (and stats.txt) holds for r's element idx: the value rounded for
 * F(ROUND), a flag 1 or 0 (report.json: true or false). */
double stats_row_report_value(const StatsCtx *c, const StatsRow *r, const int *idx);
/* r appears in mode (STATS_M_*, with STATS_M_KD when the kernel traverses a kd-tree). */
int stats_row_present(const StatsRow *r, unsigned mode);
/* r's first element (all 0; 0 when the row has none in this run), and the next, row-major. */
int stats_idx_first(const StatsCtx *c, const StatsRow *r, int *idx);
int stats_idx_next(const StatsCtx *c, const StatsRow *r, int *idx);
int stats_name_is(const char *s, size_t n, const char *name);
/* r's path as segments (at most MAX_SEGS): their count, or -1 when it does not name r's dimensions. */
int stats_path_parse(const StatsRow *r, Seg *seg);
/* Segment g's key for element idx. */
const char *stats_seg_key(const Seg *g, const StatsRow *r, const int *idx, char *buf, size_t len);
/* The path's last key if it is a literal, '_' as ' ' ("accesses with bank conflict"); else "". */
const char *stats_leaf_name(const StatsRow *r, char *buf, size_t len);
/* Every row of c's mode (and the rows null in it), in table order. */
void stats_walk(const StatsCtx *c, void (*visit)(void *w, const StatsRow *r), void *w);

#endif
