/* big.h -- big particles: the few particles much wider than the rest (a tracer).
 *
 * They would make every cell as wide as they are and every scan O(N); instead they stay
 * out of the grid's lists: each small particle's scan also checks every big one, and a
 * big one scans the block of cells within its reach, R = ceil((r_big + r_small_max) / w)
 * cells each way, and on crossing a cell wall the newly reached layer of that block. */
#ifndef GR_BIG_H
#define GR_BIG_H

#include <stdint.h>

/* Every small particle's scan checks every big one, so only a few may be big. */
#define GR_BIG_MAX 16
/* The default of big_ratio: wider than this times the median diameter is big. */
#define GR_BIG_RATIO 3.0

typedef struct {
    int32_t n;               /* how many are big */
    int32_t idx[GR_BIG_MAX]; /* their internal indices */
    uint8_t *is_big;         /* n_particles: 1 for a big one */
    double r_small;          /* largest radius of the others (all: none is big) */
} gr_big;

/* Which of n particles of the given radii are big: those wider than ratio times the
 * median diameter, if there are at most GR_BIG_MAX of them and the grid of the others
 * (cells at least cell_factor times their largest diameter wide) is fine enough that a
 * big particle's block of 2 R + 1 cells, plus a cell, is less than the box on every
 * axis: a periodic block then never meets itself, and any particle in it is less than
 * half a box away, so the nearest image is the one within reach.  `is_big` must be
 * zeroed (n entries); fills idx, n and r_small.  The one owner of this rule: the Python
 * side asks for it through granular._core.big_particles.  Returns GR_OK or
 * GR_ERR_NOMEM. */
int gr_big_choose(gr_big *b, int dim, int32_t n, const double *radius, const double *L,
                  double ratio, double cell_factor);

/* The cut: ratio times the upper median radius (radius n / 2 in increasing order);
 * wider than this is big.  GR_OK or GR_ERR_NOMEM. */
int gr_big_cut(const double *radius, int32_t n, double ratio, double *cut);

#endif
