/* sim/energy/sram.h -- an SRAM array's access energy, leakage and area from the CACTI 7 rows of
 * sim/energy/cacti7.def, and the process-node rule (docs/energy.md, "SRAM arrays", "The node").
 *
 * Owns: choosing the row for an array (the nearest in size, banks and ways, at the node asked when
 * the table has that node, else at the reference node 45 nm), scaling it to the array's size, and
 * the node exponents fitted from the rows the table has at both 45 and 22 nm. Must not: know which
 * unit an array belongs to (sim/energy/energy.c does), or read the config.
 */
#ifndef SFSIM_ENERGY_SRAM_H
#define SFSIM_ENERGY_SRAM_H

#include <stddef.h>

#define SRAM_REF_NM 45.0   /* the node every default of sim/energy/energy.def is given at */

typedef struct SramFig {
    double read_pj, write_pj;   /* per access of one 64-byte block */
    double leak_mw;             /* the whole array (every bank) */
    double area_mm2;            /* the whole array */
    /* The row used: its parameters, and the size factor applied (1: the row itself). */
    int row_cache, row_kib, row_ways, row_banks, row_nm;
    double size_factor;
} SramFig;

/* An array of kib KiB in `banks` banks (cache: tags and data, `ways`-way; ram: ways ignored) at
 * node_nm. The row is the one nearest in log2 of size (then banks, then ways) among the rows of
 * the type at node_nm, or, when the table has no row of the type at node_nm, at 45 nm, whose
 * figures are then scaled to node_nm by sram_node_scale. A size s times the row's: area and leakage
 * x s, access energy x sqrt(s) (a bit line and a word line each grow as the square root of the
 * cells). 0, or -1 when the arguments are not positive. */
int sram_figures(int cache, double kib, int ways, int banks, double node_nm, SramFig *out);

/* The exponents of the node rule: a figure at 45 nm times (node_nm / 45)^e is the figure at node_nm,
 * e fitted (the mean of log(v22 / v45) / log(22 / 45)) over the rows the table has at both nodes. */
typedef struct SramNodeExp { double dynamic, leakage, area; } SramNodeExp;
SramNodeExp sram_node_exponents(void);
/* (node_nm / 45)^e for the three kinds of figure. */
typedef struct SramNodeScale { double dynamic, leakage, area; } SramNodeScale;
SramNodeScale sram_node_scale(double node_nm);

#endif
