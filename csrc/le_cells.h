/* le_cells.h -- a sheared box's list centres in the cells: filed where the mean flow
 * carries them at a reference time, and found again from any instant (nlist.h has why).
 *
 * A list centre moves with the flow, c(t) = c + w (t - t_b) e_x with w = rate (c_y - y_c).
 * What its record keeps as x is where the flow carries it at the filing time t_ref,
 * brought into the box; `lap` holds the box lengths dropped so, so that
 *   c_x(t) = x + lap L_x + rate (t - t_ref) (c_y - y_c),
 * and the centre is filed in the cell of that x: a coordinate that does not change while
 * its list lives.  Seen from a point P at time t, a centre within R of P has a filed x
 * within R (1 + |rate (t - t_ref)|) of where the flow would carry P at t_ref; so the
 * cells to search are a window of columns that widens with |t - t_ref|, and edmd.c files
 * every centre anew (le_refile) when the strain since t_ref passes GR_NL_TILT.  Across a y
 * face the images of the flow sit a fixed offset D(t_ref) apart in this coordinate:
 * the images slide at u = rate L_y, as the flow does.
 *
 * Static functions shared by the event loop (le_nlist.h) and the checkpoint's check of
 * the lists (checkpoint.c). */
#ifndef GR_LE_CELLS_H
#define GR_LE_CELLS_H

#include <math.h>
#include <string.h>

#include "engine.h"

/* max and min of finite numbers, inline (fmax and fmin are calls here) */
static inline double le_max(double a, double b) { return a > b ? a : b; }
static inline double le_min(double a, double b) { return a < b ? a : b; }

/* floor of a number well within int32_t, without a call (the baseline x86-64 has no
 * rounding instruction) */
static inline int32_t le_floor(double x)
{
    const int32_t k = (int32_t)x;
    return k - (x < (double)k);
}

/* The x of centre record c (lap its laps) at time t, carried by the flow. */
static inline double le_centre_x(const gr_nlist *nl, const double *c, int lap, double t)
{
    return c[0] + (double)lap * nl->lx + nl->rate * (t - nl->tref) * (c[1] - nl->yc);
}

/* A sheared list's end of life and its shell's radius, fixed when it is built at time tb
 * about centre record c (y and z as built): le_shell_exit's cap (a strain, and a drift
 * of the centre along x) and the plain shell less 2^-48 (|D(tb)| + L_x), for the
 * rounding of the centre carried by the flow and of delta(t). */
static inline void le_expiry(const gr_edmd *s, const double *c, double tb, double *out)
{
    const gr_nlist *nl = &s->nl;
    const double w = nl->rate * (c[1] - nl->yc); /* the flow at the centre */
    const double life = fabs(w) * nl->life > nl->drift ? nl->drift / fabs(w) : nl->life;
    const double D = bd_le_total(s->cfg.shear_offset, s->le_u, tb);
    out[0] = tb + life;
    out[1] = nl->shell * (1.0 - 1e-9) - 0x1p-48 * (fabs(D) + s->L[0]);
}

/* File centre record c, whose x at time t is x: its x where the flow carries it at
 * t_ref, brought into the box, and *lap; returns its column. */
static inline int32_t le_file(const gr_cells *g, const gr_nlist *nl, double *c, int8_t *lap,
                              double x, double t)
{
    double X = x + nl->rate * (nl->tref - t) * (c[1] - nl->yc);
    const int32_t k = le_floor((X - g->lo[0]) / nl->lx); /* |k| <= 1: the drift is bounded */
    X -= (double)k * nl->lx;
    int8_t laps = (int8_t)k;
    if (X >= g->lo[0] + nl->lx) { /* by rounding */
        X -= nl->lx;
        laps++;
    }
    c[0] = X;
    *lap = laps;
    const int32_t f = le_floor((X - g->lo[0]) / g->w[0]);
    return f < 0 ? 0 : f >= g->nc[0] ? g->nc[0] - 1 : f;
}

/* The cells as a sheared box's list search reads them: each cell's block of GR_LE_BLOCK
 * int32, its count and its first GR_LE_SLOTS centres in the order its list holds them
 * (cells.h).  A line of cells is gathered block by block, where walking the lists took a
 * mispredicted branch at the end of nearly every cell (where a list ends is as good as
 * random).  The lists stay the state (checkpoints save them); the blocks follow them:
 * le_sync_cell wherever a cell's list changes, le_sync_all after all do. */
#define GR_LE_BLOCK 8
#define GR_LE_SLOTS (GR_LE_BLOCK - 1)

static inline void le_sync_cell(const gr_cells *g, int32_t *blocks, int32_t cell)
{
    int32_t *block = blocks + (size_t)GR_LE_BLOCK * cell, count = 0;
    for (int32_t j = g->head[cell]; j >= 0; j = g->next[j]) {
        if (count < GR_LE_SLOTS) block[1 + count] = j;
        count++;
    }
    block[0] = count;
}

static inline void le_sync_all(const gr_cells *g, int32_t *blocks)
{
    for (int32_t cell = 0; cell < g->ncells; cell++) le_sync_cell(g, blocks, cell);
}

/* A line of cells' candidates for le_gather, tested in a batch: their indices and each
 * one's wrap (the box lengths its cell's window image lies along x: -2 to 2), and what
 * the line shares.  A candidate's x offset is xline + wrap lx, its image code (less its
 * laps) code1 + inbox wrap: a cell writes its wrap for its slots in one 8-byte store,
 * where it wrote each slot's offset and code. */
#define GR_LE_BATCH 64
typedef struct {
    int32_t j[GR_LE_BATCH + 3];
    int8_t wrap[GR_LE_BATCH + 8];
    int n;
    double theta, sweep, yoff, zoff, reach, scale, xline, lx;
    int32_t inbox, self, above, code1;
} le_batch;

/* Test a batch's candidates (le_gather), appending those within reach to out (m so far);
 * returns the new count.  The separation of candidate j (centre record cj: filed x, y,
 * z, r) from the point, less its laps: dx = x + theta y + xoff, dy = y + yoff,
 * dz = z + zoff; over a list's life its x part runs from dx to dx + sweep dy.  The
 * scalar test; le_nlist.h has the same in AVX2's lanes, the same bits. */
typedef int32_t (*le_batch_test)(const gr_edmd *s, int dim, const le_batch *b, int32_t *out,
                                 int32_t m);

/* One candidate's test (as le_batch_test says), its steps in the order the lanes take. */
static inline int le_within(const double *cj, int dim, const le_batch *b, double xoff)
{
    const double dx = cj[0] + b->theta * cj[1] + xoff, ddy = cj[1] + b->yoff;
    const double end = dx + b->sweep * ddy, dx2 = dx * dx, end2 = end * end;
    double d2 = (dx * end <= 0.0 ? 0.0 : dx2 < end2 ? dx2 : end2) + ddy * ddy;
    if (dim == 3) {
        const double ddz = cj[2] + b->zoff;
        d2 += ddz * ddz;
    }
    const double cut = b->scale * (cj[dim] + b->reach);
    return d2 < cut * cut;
}

/* Append candidate k of a batch that passed: its entry, laps taken off an x image. */
static inline int32_t le_append(const gr_nlist *nl, const le_batch *b, int k, int32_t *out,
                                int32_t m)
{
    const int32_t j = b->j[k];
    out[m] = (j << GR_NL_BITS) | (b->code1 + b->inbox * (b->wrap[k] - nl->lap[j]));
    return m + ((j != b->self) & (!b->above | (j > b->self)));
}

static inline int32_t le_test_scalar(const gr_edmd *s, int dim, const le_batch *b,
                                     int32_t *out, int32_t m)
{
    for (int k = 0; k < b->n; k++)
        if (le_within(s->nl.centre + (size_t)b->j[k] * (dim + 1), dim, b,
                      b->xline + (double)b->wrap[k] * b->lx))
            m = le_append(&s->nl, b, k, out, m);
    return m;
}

/* A batch tested, its last group of four filled with copies of its first candidate (the
 * lanes past n are masked: le_nlist.h; their wraps, read with the group's, are whatever
 * bytes lie there and change nothing). */
static inline int32_t le_test_padded(const gr_edmd *s, int dim, le_batch *b, int32_t *out,
                                     int32_t m, le_batch_test test)
{
    b->j[b->n] = b->j[b->n + 1] = b->j[b->n + 2] = b->j[0];
    return test(s, dim, b, out, m);
}

/* Every particle j whose list centre, carried by the flow from time t on for a list's
 * longest life, comes within scale (r_i + r_j + 2 delta) of the point ci (x y z r at t)
 * carried likewise, through some image: as list entries (j << GR_NL_BITS | image code)
 * in out; skipping `self`, and j <= self if `above`.  The flow changes the separation
 * only along x, at rate (dy), so over the life its x part runs linearly from dx to
 * dx + sweep dy: its smallest square is 0 if that passes 0, else the smaller end's.  The
 * window's columns hold each centre once, at the image the window wraps it to: the one
 * within reach, if any.  An entry through a y face carries its y (and z) image only, one
 * within the box its x image as well (-L_x, 0 or L_x: that of the window less the
 * centre's laps).  Candidates are tested by `test` a line of cells at a time, in the
 * order the cells list them.  Returns how many. */
static GR_ALWAYS_INLINE int32_t le_gather(const gr_edmd *s, int dim, const double *ci, double t,
                                          int32_t self, int above, double scale, int32_t *out,
                                          le_batch_test test)
{
    const gr_cells *g = &s->cells;
    const gr_nlist *nl = &s->nl;
    const double Lx = nl->lx;
    le_batch b;
    b.lx = Lx;
    b.reach = ci[dim] + 2.0 * nl->shell;
    b.scale = scale;
    b.self = self;
    b.above = above;
    int32_t c[3] = {0, 0, 0};
    cell_coords(g, dim, ci, c); /* y and z: the rows; x is taken from the flow below */
    const double dref = nl->dref;
    b.theta = nl->rate * (t - nl->tref);
    b.sweep = nl->rate * nl->life;
    /* the reach at most, and room for the window's rounding */
    const double R = b.reach + nl->r_max;
    const double slack = 1e-9 * (Lx + fabs(s->le_u) * (fabs(t) + fabs(nl->tref)));
    const double xref = ci[0] - b.theta * (ci[1] - nl->yc);
    const int32_t nx = g->nc[0];
    const int nz = dim == 3 ? 3 : 1;
    int32_t m = 0;
    for (int dy = -1; dy <= 1; dy++) {
        const int32_t r = c[1] + dy;
        const int ky = r < 0 ? -1 : r >= g->nc[1] ? 1 : 0; /* the image of that row */
        const int32_t q1 = r - ky * g->nc[1];
        const double x0 = xref - (double)ky * dref - g->lo[0];
        /* the window: a centre dy = a..b above ci (the row, within reach) has a filed x
         * of x0 + dx - theta dy, where dx must come within Rx over the life: from
         * -Rx - max(0, sweep dy) to Rx - min(0, sweep dy); the extremes over the row are
         * at its ends.  Rx^2 = R^2 less the squares of the least |dy| and |dz| in the
         * line of cells (less a hair for their rounding): a line far from ci is short. */
        const double ylo = g->lo[1] + (double)r * g->w[1] - ci[1], yhi = ylo + g->w[1];
        const double ya = le_max(ylo, -R), yb = le_min(yhi, R);
        const double ymin = le_max(0.0, le_max(ylo, -yhi) - slack);
        const double lower0 = -le_max(le_max(0.0, b.sweep * ya) + b.theta * ya,
                                      le_max(0.0, b.sweep * yb) + b.theta * yb);
        const double upper0 = -le_min(le_min(0.0, b.sweep * ya) + b.theta * ya,
                                      le_min(0.0, b.sweep * yb) + b.theta * yb);
        b.yoff = (double)ky * s->L[1] - ci[1];
        b.xline = (double)ky * dref + b.theta * ((double)ky * s->L[1] - nl->yc) - ci[0];
        b.inbox = !ky; /* an x image in the entry: within the box only */
        for (int kz = 0; kz < nz; kz++) {
            const int32_t q2 = dim == 3 ? g->nb_cell[2][3 * c[2] + kz] : 0;
            const double shz = dim == 3 ? g->nb_shift[2][3 * c[2] + kz] : 0.0;
            b.zoff = shz - (dim == 3 ? ci[2] : 0.0);
            double zmin = 0.0;
            if (dim == 3) {
                const double zlo = g->lo[2] + (double)(c[2] + kz - 1) * g->w[2] - ci[2];
                zmin = le_max(0.0, le_max(zlo, -(zlo + g->w[2])) - slack);
            }
            const double rest = R * R - ymin * ymin - zmin * zmin;
            if (!(rest > 0.0)) continue; /* no centre of this line within reach */
            const double Rx = sqrt(rest);
            const int32_t K0 = le_floor((x0 + lower0 - Rx - slack) / g->w[0]);
            int32_t K1 = le_floor((x0 + upper0 + Rx + slack) / g->w[0]);
            if (K1 > K0 + nx - 1) K1 = K0 + nx - 1; /* each cell once */
            /* the image code (nlist.h nl_code), its x digit that of the box */
            b.code1 = 1 + 3 * (ky + 1) + 9 * ((shz > 0.0) - (shz < 0.0) + 1) * (dim == 3);
            const int32_t rowbase = (q2 * g->nc[1] + q1) * nx;
            int32_t n = 0; /* a local: the batch's stores might alias its count */
            /* column k of the box and the window's image `wrap` (K = k + wrap nx): -1, 0
             * or 1 in the box's rows (the x image an entry keeps); across a y face, whose
             * offset shifts the window up to a box length, -2 to 2.  Stepped along the
             * line, not found by three integer divisions a cell on the way to its
             * address */
            int32_t k = bd_cell_wrap(K0, nx), wrap = (K0 - k) / nx;
            for (int32_t K = K0; K <= K1; K++, k++) {
                if (k == nx) { /* once a line at most, where the window wraps */
                    k = 0;
                    wrap++;
                }
                const int32_t cell = rowbase + k;
                /* the cell's block, all its slots, and its wrap in eight (those past its
                 * count are overwritten or never read) */
                const int32_t *block = nl->blocks + (size_t)GR_LE_BLOCK * cell;
                const int32_t count = block[0];
                const uint64_t wraps = (uint64_t)(uint8_t)(int8_t)wrap * 0x0101010101010101u;
                memcpy(b.j + n, block + 1, GR_LE_SLOTS * sizeof *block);
                memcpy(b.wrap + n, &wraps, sizeof wraps);
                if (count <= GR_LE_SLOTS) {
                    n += count;
                } else { /* the rest from its list */
                    n += GR_LE_SLOTS;
                    for (int32_t j = g->next[block[GR_LE_SLOTS]]; j >= 0; j = g->next[j]) {
                        if (n == GR_LE_BATCH) {
                            b.n = n;
                            m = le_test_padded(s, dim, &b, out, m, test);
                            n = 0;
                        }
                        b.j[n] = j;
                        b.wrap[n++] = (int8_t)wrap;
                    }
                }
                if (n > GR_LE_BATCH - GR_LE_SLOTS) { /* room for the next cell's slots */
                    b.n = n;
                    m = le_test_padded(s, dim, &b, out, m, test);
                    n = 0;
                }
            }
            b.n = n;
            if (n) m = le_test_padded(s, dim, &b, out, m, test);
        }
    }
    return m;
}

#endif
