/* cells.h -- the cell grid: the box cut into cells at least one contact distance wide,
 * each with a singly linked list of its particles and one occupancy bit.
 *
 * A particle looks for partners in its own and the adjacent cells only.  One bit per
 * cell says whether the cell holds anyone: most cells of a dilute gas are empty (cells
 * are one diameter wide: ~8 per particle at packing 0.065), and at large N the head
 * array is far out of cache; the bits are 32 times smaller, so a scan learns which of
 * its 27 cells to visit from lines it mostly has at hand.
 *
 * Functions here know cells only; the particles' cell coordinates live in their
 * scheduling state (schedstate.h). */
#ifndef GR_CELLS_H
#define GR_CELLS_H

#include <math.h>
#include <stdint.h>

#include "common.h"

/* Cell heads beyond this many bytes are taken as out of cache, and scans ask for the
 * occupied cells' heads ahead.  In cache the extra loop only costs: its length, the number
 * of occupied cells, is as good as random, so its branch mispredicts; out of cache the
 * heads it asks for save more than that (both counted in docs/performance.md).  The event
 * loop then also prefetches events ahead (edmd.c). */
#define GR_HEADS_CACHED ((size_t)1 << 20)

typedef struct {
    int nc[3];            /* cells per axis (1 beyond dim) */
    double w[3];          /* cell widths */
    double lo[3];         /* box lower corner */
    int periodic;
    int32_t ncells;
    int32_t *head;        /* ncells: first particle of each cell, -1 none */
    int32_t *next;        /* n: the cell lists' links */
    uint64_t *occ;        /* one bit per cell, set iff it holds a particle */
    int prefetch_heads;   /* the heads take more than GR_HEADS_CACHED bytes */
    int32_t *nb_cell[3];  /* [axis][3*c + d+1]: neighbouring coordinate or -1 */
    double *nb_shift[3];  /* [axis][3*c + d+1]: image shift in box lengths */
    /* Linear index offsets of the adjacent cells of a cell away from the box edge (the
     * common case, which then needs no wrapping and no image shifts): all of them, and
     * the layer newly adjacent after a crossing along axis a in direction up/down. */
    int32_t off_all[27];
    int32_t off_layer[6][9];
    /* The same cells as rows of three along x, by the offset of each row's middle cell
     * (the layers across y and z; a layer across x has no such rows), in the same order:
     * a scan reads a row's occupancy in one go (cell_row). */
    int32_t row_all[9];
    int32_t row_layer[6][3];
} gr_cells;

/* An occupied cell next to another and the image shift to add to positions found there. */
typedef struct {
    int32_t cell;
    double shift[3];
} gr_nbr;

/* Cells per axis for cells at least `width` wide in a box of sides L (written to k),
 * capped at a few cells per particle; returns the total. */
double gr_cells_dims(int dim, int64_t n, const double *L, double width, double k[3]);
/* Build an empty grid of cells at least `width` wide for n particles.  Returns GR_OK,
 * GR_ERR_VALUE (too many cells, err filled) or GR_ERR_NOMEM. */
int gr_cells_build(gr_cells *g, int dim, int32_t n, const double *lo, const double *L,
                   int periodic, double width, gr_error *err);
void gr_cells_free(gr_cells *g);
/* Empty every cell (the links of the particles are left to the caller). */
void gr_cells_clear(gr_cells *g);

/* The linear index of the cell at coordinates c. */
static inline int32_t cell_of(const gr_cells *g, int dim, const int32_t *c)
{
    return dim == 3 ? (c[2] * g->nc[1] + c[1]) * g->nc[0] + c[0] : c[1] * g->nc[0] + c[0];
}

static inline int cell_occupied(const gr_cells *g, int32_t c)
{
    return (int)((g->occ[c >> 6] >> (c & 63)) & 1);
}

/* The occupied ones among the count cells base + off[k], in that order, written to out
 * without a branch (which are occupied is as good as random); returns how many. */
static inline int cells_occupied(const gr_cells *g, int32_t base, const int32_t *off,
                                 int count, int32_t *out)
{
    int m = 0;
    for (int k = 0; k < count; k++) {
        const int32_t cell = base + off[k];
        out[m] = cell;
        m += cell_occupied(g, cell);
    }
    return m;
}

/* 64-bit words of occupancy bits for ncells cells, with one to spare: cell_row reads
 * the word after the last cell's. */
static inline size_t cell_occ_words(int32_t ncells) { return ((size_t)ncells + 63) / 64 + 1; }

/* The occupancy of cells mid - 1, mid, mid + 1 (mid >= 1) as bits 0, 1, 2. */
static inline unsigned cell_row(const gr_cells *g, int32_t mid)
{
    const uint32_t k = (uint32_t)mid - 1, sh = k & 63;
    const uint64_t lo = g->occ[k >> 6], hi = g->occ[(k >> 6) + 1];
    return (unsigned)(((lo >> sh) | (hi << (63 - sh) << 1)) & 7);
}

/* i becomes the first of cell c's list (a scan meets the cell's particles in the order
 * they were filed, latest first). */
static inline void cell_insert(gr_cells *g, int32_t i, int32_t c)
{
    const int32_t first = g->head[c];
    g->next[i] = first;
    if (first < 0) g->occ[c >> 6] |= (uint64_t)1 << (c & 63);
    g->head[c] = i;
}

/* i leaves cell c's list, the others keeping their order.  Singly linked: the walk from
 * the head to i reads the links a scan of the cell reads anyway (a cell holds a particle
 * or two), where back links cost a random access to the neighbours' links at every
 * crossing (counted in docs/performance.md). */
static inline void cell_remove(gr_cells *g, int32_t i, int32_t c)
{
    int32_t *link = &g->head[c];
    while (*link != i) link = &g->next[*link];
    *link = g->next[i];
    if (g->head[c] < 0) g->occ[c >> 6] &= ~((uint64_t)1 << (c & 63));
}

/* The coordinates c of the cell holding position x (clamped: rounding may leave a
 * particle a hair outside the box). */
static inline void cell_coords(const gr_cells *g, int dim, const double *x, int32_t *c)
{
    for (int a = 0; a < dim; a++) {
        double f = floor((x[a] - g->lo[a]) / g->w[a]);
        c[a] = !(f >= 0.0) ? 0 : f >= g->nc[a] ? g->nc[a] - 1 : (int32_t)f; /* NaN: 0 */
    }
}

/* Whether cell coordinates c are away from the box edge (1 <= c[a] <= nc[a] - 2, in one
 * unsigned comparison per axis): then off_all / off_layer apply without wrapping. */
static inline int cell_interior(const gr_cells *g, int dim, const int32_t *c)
{
    int interior = 1;
    for (int a = 0; a < dim; a++) interior &= (uint32_t)(c[a] - 1) < (uint32_t)(g->nc[a] - 2);
    return interior;
}

/* The occupied cells adjacent to cell coordinates c (itself included), with the image
 * shift to add to positions found there.  With axis >= 0 only the layer at offset dir
 * along that axis (the cells that become adjacent when crossing in that direction).
 * Returns the count.  The general way, for cells at the box edge: every candidate cell
 * is looked at in a loop of fixed length and kept or not without a branch, because
 * which of them are occupied, or beyond a wall, is as good as random. */
static GR_ALWAYS_INLINE int cell_neighbours_in(const gr_cells *g, int dim, const int32_t *c,
                                               int axis, int dir, gr_nbr *out,
                                               const int periodic)
{
    /* the offsets along each axis: -1, 0, 1, or along `axis` only dir (three times) */
    int d[3][3];
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < 3; k++) d[a][k] = a == axis ? dir : k - 1;
    const int n2 = dim == 3 && axis != 2 ? 3 : 1, n1 = axis != 1 ? 3 : 1, n0 = axis != 0 ? 3 : 1;
    int m = 0;
    for (int k2 = 0; k2 < n2; k2++) {
        const int32_t q2 = dim == 3 ? g->nb_cell[2][3 * c[2] + d[2][k2] + 1] : 0;
        const double sh2 = dim == 3 ? g->nb_shift[2][3 * c[2] + d[2][k2] + 1] : 0.0;
        for (int k1 = 0; k1 < n1; k1++) {
            const int32_t q1 = g->nb_cell[1][3 * c[1] + d[1][k1] + 1];
            const double sh1 = g->nb_shift[1][3 * c[1] + d[1][k1] + 1];
            for (int k0 = 0; k0 < n0; k0++) {
                const int32_t q0 = g->nb_cell[0][3 * c[0] + d[0][k0] + 1];
                /* not beyond a wall (a periodic box has none) */
                const int inside = periodic | ((q0 >= 0) & (q1 >= 0) & (q2 >= 0));
                const int32_t cell = inside ? (q2 * g->nc[1] + q1) * g->nc[0] + q0 : 0;
                out[m].cell = cell;
                out[m].shift[0] = g->nb_shift[0][3 * c[0] + d[0][k0] + 1];
                out[m].shift[1] = sh1;
                out[m].shift[2] = sh2;
                m += inside & cell_occupied(g, cell);
            }
        }
    }
    return m;
}

/* Compiled apart for periodic boxes, where no neighbour lies beyond a wall: a small box
 * has many edge cells, and the wall tests cost them instructions (docs/performance.md). */
static inline int cell_neighbours(const gr_cells *g, int dim, const int32_t *c, int axis,
                                  int dir, gr_nbr *out)
{
    return g->periodic ? cell_neighbours_in(g, dim, c, axis, dir, out, 1)
                       : cell_neighbours_in(g, dim, c, axis, dir, out, 0);
}

#endif
