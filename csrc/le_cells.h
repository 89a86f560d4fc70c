/* le_cells.h -- a sheared box's list centres in the cells: filed where the mean flow
 * carries them at a reference time, and found again from any instant (nlist.h has why).
 *
 * A list centre c_j built at t_j moves with the flow, c_j(t) = c_j + w_j (t - t_j) e_x with
 * w_j = rate (c_j,y - y_c).  It is filed in the cell of c_j(t_ref): a coordinate that does
 * not change while its list lives.  Seen from a point P at time t, a centre within R of
 * P has |x_j(t_ref) - P_x(t_ref)| <= R (1 + |rate (t - t_ref)|), P_x(t_ref) being where the
 * flow would carry P at t_ref; so the cells to search are a window of columns that widens
 * with |t - t_ref|, and edmd.c files every centre anew (le_refile) when it grows past a
 * quarter of R.  Across a y face the flow's images sit a fixed offset D(t_ref) apart in
 * this coordinate, because the images slide at u = rate L_y, as the flow does.
 *
 * Static functions shared by the event loop (le_nlist.h) and the checkpoint's check of
 * the lists (checkpoint.c). */
#ifndef GR_LE_CELLS_H
#define GR_LE_CELLS_H

#include <math.h>

#include "engine.h"

/* The x of centre c (built at tb) carried by the flow to time t. */
static inline double le_centre_x(const gr_nlist *nl, const double *c, double tb, double t)
{
    return c[0] + nl->rate * (c[1] - nl->yc) * (t - tb);
}

/* The column of the cell a centre c built at tb is filed in: that of where the flow
 * carries it at t_ref, wrapped around the box. */
static inline int32_t le_column(const gr_cells *g, const gr_nlist *nl, const double *c, double tb)
{
    const double f = floor((le_centre_x(nl, c, tb, nl->tref) - g->lo[0]) / g->w[0]);
    return bd_cell_wrap((int32_t)f, g->nc[0]); /* |f| stays below ~2 nc (nlist.h) */
}

/* Every particle j whose list centre, carried by the flow from time t on for a list's
 * longest life, comes within scale (r_i + r_j + 2 delta) of the point ci (radius ci[dim])
 * carried likewise, through some image: as list entries (j << GR_NL_BITS | image code)
 * in out; skipping `self`, and j <= self if `above`.  The flow changes the separation
 * only along x, at rate (dy), so over the life its x part runs linearly from dx to
 * dx + sweep dy: its smallest square is 0 if that passes 0, else the smaller end's.  An
 * entry through a y face carries its y (and z) image only, one within the box its x image
 * as well (-L_x, 0 or L_x).  Returns how many. */
static int32_t le_gather(const gr_edmd *s, int dim, const double *ci, double t, int32_t self,
                         int above, double scale, int32_t *out)
{
    const gr_cells *g = &s->cells;
    const gr_nlist *nl = &s->nl;
    const double Lx = s->L[0], reach = ci[dim] + 2.0 * nl->shell;
    int32_t c[3] = {0, 0, 0};
    cell_coords(g, dim, ci, c); /* y and z: the rows; x is taken from the flow below */
    const double delta = bd_le_offset(s->cfg.shear_offset, s->le_u, t, Lx);
    const double dref = bd_le_offset(s->cfg.shear_offset, s->le_u, nl->tref, Lx);
    /* the window's half width in the filing coordinate, with room for its rounding */
    const double tilt = fabs(nl->rate * (t - nl->tref));
    const double sweep = nl->rate * nl->life;
    const double half = (reach + nl->r_max) * (1.0 + tilt + fabs(sweep)) +
                        1e-9 * (Lx + fabs(s->le_u) * (fabs(t) + fabs(nl->tref)));
    const double xref = le_centre_x(nl, ci, t, nl->tref);
    const int32_t nx = g->nc[0];
    const int nz = dim == 3 ? 3 : 1;
    int32_t m = 0;
    for (int dy = -1; dy <= 1; dy++) {
        const int32_t r = c[1] + dy;
        const int ky = r < 0 ? -1 : r >= g->nc[1] ? 1 : 0; /* the image of that row */
        const int32_t q1 = r - ky * g->nc[1];
        const double x0 = xref - (double)ky * dref - g->lo[0];
        const int32_t K0 = (int32_t)floor((x0 - half) / g->w[0]);
        int32_t K1 = (int32_t)floor((x0 + half) / g->w[0]);
        if (K1 > K0 + nx - 1) K1 = K0 + nx - 1; /* each cell once */
        const double yoff = (double)ky * s->L[1] - ci[1], xoff = (double)ky * delta;
        for (int kz = 0; kz < nz; kz++) {
            const int32_t q2 = dim == 3 ? g->nb_cell[2][3 * c[2] + kz] : 0;
            const double shz = dim == 3 ? g->nb_shift[2][3 * c[2] + kz] : 0.0;
            const double zoff = shz - (dim == 3 ? ci[2] : 0.0);
            /* the image code (nlist.h nl_code) but for its x digit */
            const int32_t code0 = 3 * (ky + 1) + 9 * ((shz > 0.0) - (shz < 0.0) + 1) * (dim == 3);
            const int32_t rowbase = (q2 * g->nc[1] + q1) * nx;
            for (int32_t K = K0; K <= K1; K++) {
                const int32_t cell = rowbase + bd_cell_wrap(K, nx);
                if (!cell_occupied(g, cell)) continue;
                for (int32_t j = g->head[cell]; j >= 0; j = g->next[j]) {
                    const double *cj = nl->centre + (size_t)j * (dim + 1);
                    /* the centres stay within L_x / 4 of the box (nlist.h): one step */
                    const double raw = le_centre_x(nl, cj, nl->built[j], t) - ci[0];
                    double dx;
                    int32_t sx = 0;
                    if (ky) {
                        dx = bd_nearest(bd_nearest(raw, Lx) + xoff, Lx);
                    } else {
                        sx = (raw < -0.5 * Lx) - (raw > 0.5 * Lx);
                        dx = raw + (double)sx * Lx;
                    }
                    const double ddy = cj[1] + yoff, end = dx + sweep * ddy;
                    const double dx2 = dx * dx, end2 = end * end;
                    double d2 = (dx * end <= 0.0 ? 0.0 : dx2 < end2 ? dx2 : end2) + ddy * ddy;
                    if (dim == 3) {
                        const double ddz = cj[2] + zoff;
                        d2 += ddz * ddz;
                    }
                    const double cut = scale * (cj[dim] + reach);
                    out[m] = (j << GR_NL_BITS) | (code0 + sx + 1);
                    m += (d2 < cut * cut) & (j != self) & (!above | (j > self));
                }
            }
        }
    }
    return m;
}

#endif
