/* le_nlist.h -- neighbour lists in a sheared (Lees-Edwards) box: the list search across a
 * sliding face, the scan through the sliding images, the shrinking shells' exits.  Why
 * these keep the lists exact is in nlist.h.
 *
 * Static functions included by search.h (so by edmd.c only), reached only when the box
 * is sheared (s->le): the plain loop never runs them.  In 3D on AVX2 CPUs the scan runs
 * in four lanes instead (scan_avx2.h scan_list_avx2_sheared, the same bits). */
#ifndef GR_LE_NLIST_H
#define GR_LE_NLIST_H

#include <math.h>

#include "engine.h"

/* The first column of the five whose images, displaced by ky delta, can hold a centre
 * within a cell width (>= the lists' reach) of x: the column the image of x falls in,
 * less two (one for the reach, one to spare for rounding). */
static inline int32_t le_window(const gr_cells *g, double x, int ky, double delta)
{
    return (int32_t)floor((x - g->lo[0] - (double)ky * delta) / g->w[0]) - 2;
}

/* find_near for a centre in a cell next to a y face (c[1] in an edge row): the rows
 * within the box as cells.h tabulates them, the row across the face through the window
 * of five columns at delta now (le_window).  Entries through the face carry their y
 * (and z) image only (nl_code with no x shift): the scans take the x image nearest at
 * their time. */
static int32_t le_find_near(gr_edmd *s, int dim, int32_t i, int above)
{
    const gr_cells *g = &s->cells;
    const double *ci = s->nl.centre + (size_t)i * (dim + 1);
    const double reach = ci[dim] + 2.0 * s->nl.shell;
    const int32_t *c = s->sched[i].c, nx = g->nc[0];
    const double t = TIME(rec(s, dim, i), dim);
    const double delta = bd_le_offset(s->cfg.shear_offset, s->le_u, t, s->L[0]);
    const int nz = dim == 3 ? 3 : 1;
    int32_t m = 0;
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
                    const int32_t cell = rowbase + g->nb_cell[0][3 * c[0] + kx];
                    if (cell_occupied(g, cell))
                        m = near_in_cell(s, dim, i, ci, reach, cell, shift, nl_code(dim, shift),
                                         above, m);
                }
                continue;
            }
            const int32_t code = nl_code(dim, shift); /* shift[0] = 0: no x image */
            const int32_t K0 = le_window(g, ci[0], ky, delta);
            for (int32_t K = K0; K < K0 + 5; K++) {
                const int32_t k = bd_cell_wrap(K, nx);
                if (!cell_occupied(g, rowbase + k)) continue;
                shift[0] = (double)ky * delta + (double)((K - k) / nx) * s->L[0];
                m = near_in_cell(s, dim, i, ci, reach, rowbase + k, shift, code, above, m);
            }
        }
    }
    return m;
}

/* One listed candidate j through a y face (image shift sh: y and z; ky = sign of its y):
 * as try_pair, with the x image nearest now, displaced by ky delta, and moving with ky u
 * (as do_pair_sheared finds it at the collision). */
static inline void le_try_listed(const gr_edmd *s, int dyn, int dim, int32_t i, const double *p,
                                 int32_t j, const double *sh, double delta, double *best,
                                 int32_t *partner)
{
    const double *q = rec(s, dim, j);
    const double ky = sh[1] > 0.0 ? 1.0 : -1.0;
    double dtj = TIME(p, dim) - TIME(q, dim), dr[3], dv[3];
    for (int a = 0; a < dim; a++) {
        dr[a] = fl_sep(dyn, q[a], VEL(q, dim)[a], s->cfg.gravity[a], dtj, p[a]);
        if (a) dr[a] += sh[a];
        dv[a] = fl_relvel(dyn, VEL(q, dim)[a], VEL(p, dim)[a], s->cfg.gravity[a], dtj);
    }
    /* positions stray up to a shell beyond the box: |dr| < 3 L / 2 for each nearest */
    dr[0] = bd_nearest(bd_nearest(dr[0], s->L[0]) + ky * delta, s->L[0]);
    dv[0] += ky * s->le_u;
    double dt;
    if (!fl_pair_beats(dyn, dim, dr, dv, RAD(p, dim) + RAD(q, dim), *best, &dt)) return;
    if (rebound_now(s, i, j, TIME(p, dim), dt)) return;
    *best = dt;
    *partner = j;
}

/* scan_list in a sheared box: entries within the box or through an x or z face as
 * there, those through a y face through the sliding image. */
static void le_scan_list(gr_edmd *s, int dyn, int dim, int32_t i)
{
    const double *p = rec(s, dim, i);
    gr_sched *e = &s->sched[i];
    const int32_t *row = nl_row(&s->nl, i);
    const double delta = bd_le_offset(s->cfg.shear_offset, s->le_u, TIME(p, dim), s->L[0]);
    double best = (e->t_coll < e->t_cross ? e->t_coll : e->t_cross) - TIME(p, dim);
    int32_t partner = -1;
    for (int k = 0; k < e->nn; k++) {
        const int32_t j = row[k] >> GR_NL_BITS;
        const double *sh = s->nl.img[row[k] & GR_NL_CODE_MASK];
        if (sh[1] == 0.0) try_pair(s, dyn, dim, i, p, j, sh, 0, &best, &partner);
        else le_try_listed(s, dyn, dim, i, p, j, sh, delta, &best, &partner);
    }
    keep_pair(s, dim, i, best, partner);
}

/* The radius a shrinking shell built at tb has at time t: delta less the plain shell's
 * hair (nlist.c), less 2^-48 (|D(tb)| + L_x) for delta(t)'s rounding (the offset's
 * ulp at most, at the build and at a scan), less the shrink |u|/2 (t - tb). */
static inline double le_shell_radius(const gr_edmd *s, double tb, double t)
{
    const double D = bd_le_total(s->cfg.shear_offset, s->le_u, tb);
    return s->nl.shell * (1.0 - 1e-9) - 0x1p-48 * (fabs(D) + s->L[0]) - s->nl.shrink * (t - tb);
}

/* List mode in a sheared box, i's clock at the present: its shell exit (shrinking next to
 * a y face, nlist.h); edmd.c predict then scans its list (le_scan_list, or in 3D on AVX2
 * CPUs scan_list_avx2_sheared: the same bits). */
static void le_shell_exit(gr_edmd *s, int dyn, int dim, int32_t i)
{
    const double *p = rec(s, dim, i), *centre = s->nl.centre + (size_t)i * (dim + 1);
    const double tb = s->nl.built[i], t = TIME(p, dim);
    const double exit =
        tb < INFINITY ? fl_shrink_exit_time(dyn, dim, p, VEL(p, dim), s->cfg.gravity, centre,
                                            le_shell_radius(s, tb, t), s->nl.shrink)
                      : fl_exit_time(dyn, dim, p, VEL(p, dim), s->cfg.gravity, centre,
                                     s->nl.exit2);
    s->sched[i].t_cross = t + exit;
}

#endif
