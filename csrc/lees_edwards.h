/* lees_edwards.h -- the cells across a sheared face (boundary.h, "Lees-Edwards"): who a
 * particle in the top or bottom row of cells can meet through the sliding images, and how
 * long that answer holds.
 *
 * Static functions included by search.h (so by edmd.c only), called from scan_cells'
 * edge-cell branch when the box is sheared: the plain loop never reaches them.
 *
 * The images across a y face slide along x at u = (shear rate) L_y.  A particle in
 * column c of an edge row meets, through that face, the particles of the columns whose
 * images overlap columns c-1 .. c+1.  With the images displaced by delta in
 * [M w, (M+1) w] (w the cell width along x, M an integer), those are the columns
 * c-M-2 .. c-M+1 (c-M-1 .. c-M+1 at the ends of that range).  The scan takes six,
 * c-M-3 .. c-M+2: one column to spare each way, so that rounding in delta or in the
 * particle's cell never loses a pair (a pair that touches only at the exact edge of its
 * cells is kept either way).
 *
 * The set is right while delta stays in [M w, (M+1) w]: the images slide on, and a
 * particle sitting still near the face meets new ones without any event of its own.  So
 * M comes from the time, not from delta: the "slide" index S counts the cell widths the
 * images have passed (le_slide_index), M follows from it, and each edge particle gets a
 * "slide" event at the time S next grows (kept in its collision prediction with partner
 * code GR_LE_SLIDE: its event rescans).  No prediction of an edge particle outlives its
 * slide, so a pair that the slide brings within reach is found by the rescan before it can
 * touch.  Slide times are computed from S by one formula (le_slide_time), monotone in S,
 * and the index of a time is corrected against them, so an event at a slide time always
 * gets the next index and the next slide lies strictly later. */
#ifndef GR_LEES_EDWARDS_H
#define GR_LEES_EDWARDS_H

#include <math.h>

#include "engine.h"

/* The partner code of a slide event (as a wall "2 * dim", past the walls' codes) */
#define GR_LE_SLIDE(dim) (-2 - 2 * (dim))

/* Whether cell coordinate c1 along y is in an edge row (next to a sheared face): 0 or
 * nc - 1, one unsigned comparison (which rows a particle is in is as good as random). */
static inline int le_edge_row(const gr_cells *g, int32_t c1)
{
    return (uint32_t)(c1 - 1) >= (uint32_t)(g->nc[1] - 2);
}

/* The time at which the images have slid S cell widths w from the phase at time 0:
 * the phase is (sign(u) d0 + |u| t) / w (delta grows with u > 0, falls with u < 0). */
static inline double le_slide_time(const gr_edmd *s, int64_t S)
{
    const double u = s->le_u, w = s->cells.w[0];
    const double d0 = u > 0.0 ? s->cfg.shear_offset : -s->cfg.shear_offset;
    return ((double)S * w - d0) / fabs(u);
}

/* The slide index S of time t: le_slide_time(S) <= t < le_slide_time(S + 1) (as far as
 * the double S can tell). */
static inline int64_t le_slide_index(const gr_edmd *s, double t)
{
    const double u = s->le_u, w = s->cells.w[0];
    const double d0 = u > 0.0 ? s->cfg.shear_offset : -s->cfg.shear_offset;
    const double phase = floor((d0 + fabs(u) * t) / w);
    int64_t S = phase > 4e18 ? (int64_t)4e18 : phase < -4e18 ? (int64_t)-4e18 : (int64_t)phase;
    for (int k = 0; k < 4 && le_slide_time(s, S + 1) <= t; k++) S++;
    for (int k = 0; k < 4 && le_slide_time(s, S) > t; k++) S--;
    return S;
}

/* The next slide after t, strictly later. */
static inline double le_next_slide(const gr_edmd *s, double t)
{
    const double next = le_slide_time(s, le_slide_index(s, t) + 1);
    return next > t ? next : nextafter(t, INFINITY);
}

/* One candidate j of i (record p) seen through a sliding image: positions shifted by
 * shift, j's velocity along x by vx.  As try_pair (search.h), with the image's speed. */
static inline void le_try_pair(const gr_edmd *s, int dyn, int dim, int32_t i, const double *p,
                               int32_t j, const double *shift, double vx, double *best,
                               int32_t *partner)
{
    const double *q = rec(s, dim, j);
    double dtj = TIME(p, dim) - TIME(q, dim), dr[3], dv[3];
    for (int a = 0; a < dim; a++) {
        dr[a] = fl_sep(dyn, q[a], VEL(q, dim)[a], s->cfg.gravity[a], dtj, p[a]) + shift[a];
        dv[a] = fl_relvel(dyn, VEL(q, dim)[a], VEL(p, dim)[a], s->cfg.gravity[a], dtj);
    }
    dv[0] += vx;
    double dt;
    if (!fl_pair_beats(dyn, dim, dr, dv, RAD(p, dim) + RAD(q, dim), *best, &dt)) return;
    if (rebound_now(s, i, j, TIME(p, dim), dt)) return;
    *best = dt;
    *partner = j;
}

/* The particles of one cell through a shift; vx != 0: a sliding image. */
static inline void le_scan_cell(const gr_edmd *s, int dyn, int dim, int32_t i, const double *p,
                                int32_t cell, const double *shift, double vx, double *best,
                                int32_t *partner)
{
    if (!cell_occupied(&s->cells, cell)) return;
    for (int32_t j = s->cells.head[cell]; j >= 0; j = s->cells.next[j])
        if (j != i) le_try_pair(s, dyn, dim, i, p, j, shift, vx, best, partner);
}

/* Cell mode, sheared box, i in an edge row (clock at the present): its slide event, then
 * pair collisions with every particle of the adjacent cells, those across a y face
 * through the sliding window of columns.  Scans every neighbour (not only a layer newly
 * adjacent): an edge particle's neighbours change with time. */
static void le_scan_edge(gr_edmd *s, int dyn, int dim, int32_t i, double *best, int32_t *partner)
{
    const gr_cells *g = &s->cells;
    const double *p = rec(s, dim, i);
    const int32_t *c = s->sched[i].c;
    gr_sched *e = &s->sched[i];
    const double t = TIME(p, dim);
    const double slide = le_next_slide(s, t);
    if (slide < e->t_coll) {
        e->t_coll = slide;
        e->partner = GR_LE_SLIDE(dim);
        *best = slide - t;
    }
    const int64_t S = le_slide_index(s, t);
    const int32_t nx = g->nc[0];
    /* delta in [M w, (M + 1) w] (mod L_x): M = S for u > 0, -S - 1 for u < 0 */
    const int32_t M = (int32_t)(((s->le_u > 0.0 ? S : -S - 1) % nx + nx) % nx);
    const double delta = bd_le_offset(s->cfg.shear_offset, s->le_u, t, s->L[0]);
    const int nz = dim == 3 ? 3 : 1;
    for (int dy = -1; dy <= 1; dy++) {
        const int32_t r = c[1] + dy;
        const int ky = r < 0 ? -1 : r >= g->nc[1] ? 1 : 0; /* the image of that row */
        const int32_t q1 = r - ky * g->nc[1];
        for (int kz = 0; kz < nz; kz++) {
            const int32_t q2 = dim == 3 ? g->nb_cell[2][3 * c[2] + kz] : 0;
            double shift[3] = {0.0, (double)ky * s->L[1],
                               dim == 3 ? g->nb_shift[2][3 * c[2] + kz] : 0.0};
            const int32_t rowbase = (q2 * g->nc[1] + q1) * nx;
            if (!ky) {
                for (int kx = 0; kx < 3; kx++) {
                    shift[0] = g->nb_shift[0][3 * c[0] + kx];
                    le_scan_cell(s, dyn, dim, i, p, rowbase + g->nb_cell[0][3 * c[0] + kx], shift,
                                 0.0, best, partner);
                }
                continue;
            }
            /* the image row displaced by ky delta, in [Mi w, (Mi + 1) w] */
            const int32_t Mi = ky > 0 ? M : -M - 1;
            for (int32_t K = c[0] - Mi - 3; K <= c[0] - Mi + 2; K++) {
                const int32_t k = bd_cell_wrap(K, nx);
                shift[0] = (double)ky * delta + (double)((K - k) / nx) * s->L[0];
                le_scan_cell(s, dyn, dim, i, p, rowbase + k, shift, (double)ky * s->le_u, best,
                             partner);
            }
        }
    }
}

#endif
