/* boundary.h -- the boundary seam: what the faces of the box do.  Which image of a
 * neighbour a particle sees, how a particle re-enters the box, where a wall stops a
 * centre and which cells lie beyond a face: the cells (cells.c), the neighbour lists
 * (nlist.c), the pair predictions and collisions (search.h, edmd.c), the samples and the
 * state (sample.c) and the checks (validate.c) ask here and write no image arithmetic
 * of their own.
 *
 * Two kinds today, gr_edmd_config.periodic: GR_BOUNDARY_WALLS (0, reflecting walls) and
 * GR_BOUNDARY_PERIODIC (1, every axis).  The loop tests the kind at run time where that
 * costs nothing and compiles the crossing prediction and the edge cells' neighbours apart
 * for it where it does (edmd.c predict_cross, cells.h cell_neighbours).
 *
 * Lees-Edwards (sliding images, for shear) comes next.  It needs here:
 *  - a time-dependent image shift: an image across the y faces is displaced along x by
 *    +-(shear rate) L_y t (taken modulo L_x) and moves with +-(shear rate) L_y along x, so
 *    bd_shift takes the axis, the time and the image along y, and the pair's relative
 *    velocity through such an image gains that speed (flight.h's fl_relvel stays the
 *    same for the other images);
 *  - bd_through_face across a y face also changes x (by the displacement) and v_x (by the
 *    speed), and the image counters then no longer give the unwrapped x alone (bd_unwrap
 *    adds the accumulated displacement, kept per particle);
 *  - the tables built once from fixed shifts -- the cells' nb_shift (cells.c) and the
 *    neighbour lists' image codes (nlist.c img) -- hold for x and z only: across y the
 *    shift is computed from the time at each use, and the x neighbours of a cell across a
 *    y face shift by a whole number of cells and a remainder (one more cell column to
 *    scan);
 *  - bd_nearest along x for a pair whose y separation goes through an image takes the
 *    displaced image. */
#ifndef GR_BOUNDARY_H
#define GR_BOUNDARY_H

#include <stdint.h>

enum {
    GR_BOUNDARY_WALLS = 0,   /* reflecting walls on every axis */
    GR_BOUNDARY_PERIODIC = 1 /* periodic on every axis */
};

/* ---- images (periodic) ---- */

/* The separation d along an axis of periodic length L seen through the nearest image
 * (|d| < 3L/2, as between particles in the box). */
static inline double bd_nearest(double d, double L)
{
    return d > 0.5 * L ? d - L : d < -0.5 * L ? d + L : d;
}

/* The shift that brings image k (-1, 0, 1) of a particle next to the box, along an axis of
 * length L. */
static inline double bd_shift(int k, double L) { return (double)k * L; }

/* Cell coordinate q (one step from a cell in 0..m-1) on an axis of length L: the cell it
 * names, wrapped around a periodic box with the image shift to add to positions found
 * there (*shift), or -1 beyond a wall. */
static inline int bd_cell_step(int q, int m, int periodic, double L, double *shift)
{
    *shift = 0.0;
    if (q >= 0 && q < m) return q;
    if (!periodic) return -1;
    if (q < 0) {
        *shift = bd_shift(-1, L);
        return q + m;
    }
    *shift = bd_shift(1, L);
    return q - m;
}

/* A cell coordinate k (any integer) wrapped into 0..m-1 (periodic). */
static inline int32_t bd_cell_wrap(int32_t k, int32_t m) { return (k % m + m) % m; }

/* Whether a cell lies beyond the face of cell c (of 0..nc-1) that a particle moving up (1)
 * or down (0) reaches; without a branch (which it is, is as good as random).  A periodic
 * box has one behind every face: callers test walls only. */
static inline int bd_cell_beyond(int up, int32_t c, int32_t nc)
{
    return (up & (c < nc - 1)) | (!up & (c > 0));
}

/* ---- re-entry (periodic) ---- */

/* A particle at *x leaves through the upper (up = 1) or lower face of an axis of length L:
 * it re-enters at the other, and its image counter *img follows. */
static inline void bd_through_face(double *x, double L, int64_t *img, int up)
{
    if (up) {
        *x -= L;
        ++*img;
    } else {
        *x += L;
        --*img;
    }
}

/* A particle at *x, at most one box length out of [lo, hi) (length L), brought back in,
 * its image counter *img following; returns 1 if it moved. */
static inline int bd_reenter(double *x, double lo, double hi, double L, int64_t *img)
{
    if (*x >= hi) {
        bd_through_face(x, L, img, 1);
        return 1;
    }
    if (*x < lo) {
        bd_through_face(x, L, img, 0);
        return 1;
    }
    return 0;
}

/* The unwrapped coordinate of x in image img of an axis of length L. */
static inline double bd_unwrap(double x, int64_t img, double L) { return x + (double)img * L; }

/* ---- walls ---- */

/* Where a wall at lo (below) or hi (above) stops the centre of a particle of radius r. */
static inline double bd_wall_stop_lo(double lo, double r) { return lo + r; }
static inline double bd_wall_stop_hi(double hi, double r) { return hi - r; }

/* Whether coordinate x of a particle of radius r lies outside [lo, hi] at the start: for
 * walls the whole particle must be inside (with slack for rounding), for a periodic box
 * its centre. */
static inline int bd_outside(int periodic, double x, double r, double lo, double hi,
                             double slack)
{
    return periodic ? (x < lo || x > hi) : (x - r < lo - slack || x + r > hi + slack);
}

#endif
