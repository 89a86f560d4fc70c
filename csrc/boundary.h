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
 * Lees-Edwards (sliding images, for shear): a periodic box with a shear rate != 0 (edmd.h
 * gr_edmd_config.shear_rate; flow along x, gradient along y, the only pair offered).  The
 * image across the upper y face is displaced along x by delta(t) and moves with
 * u = (shear rate) L_y along x; the one across the lower face by -delta(t), with -u.
 *  - delta(t) = D(t) mod L_x with D(t) = shear_offset + u t, computed from the absolute
 *    time at each use (bd_le_offset): no state that could drift, so a long run, a
 *    checkpoint and its continuation all see the same bits.  Its resolution is that of
 *    the time itself times u (the position error of a particle moving at u);
 *  - a particle leaving through the upper face re-enters at the lower one with x - delta
 *    and v_x - u (through the lower face: x + delta, v_x + u), edmd.c do_face_sheared;
 *  - unwrapped x = x + img_x L_x + img_y D(t) (bd_le_unwrap): continuous through a
 *    crossing (img_x takes the whole box lengths of D that delta drops) and it moves with
 *    the particle's velocity in the unfolded lattice, v_x + img_y u;
 *  - a pair whose y separation goes through an image sees the partner's x displaced by
 *    -+delta and its v_x by -+u (bd_le_image);
 *  - the cells across a y face slide: lees_edwards.h scans them and bounds how long a
 *    prediction there may live (a "slide" event each time the images pass one cell);
 *    neighbour lists move with the mean flow and take the nearest x image through a y
 *    face at each scan (le_cells.h, le_nlist.h; nlist.h has why no pair is missed). */
#ifndef GR_BOUNDARY_H
#define GR_BOUNDARY_H

#include <math.h>
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

/* ---- Lees-Edwards (sliding images across the y faces) ---- */

/* The accumulated image offset D(t) = d0 + u t (d0: the offset at time 0, u: the image
 * speed (shear rate) L_y), and delta(t) = D(t) mod L_x in [0, L_x). */
static inline double bd_le_total(double d0, double u, double t) { return d0 + u * t; }
static inline double bd_le_offset(double d0, double u, double t, double Lx)
{
    double d = fmod(bd_le_total(d0, u, t), Lx);
    if (d < 0.0) d += Lx;
    return d < Lx ? d : 0.0; /* -tiny + Lx rounds to Lx */
}

/* The unwrapped x of a particle at x with image counters img_x, img_y (convention above). */
static inline double bd_le_unwrap(double x, int64_t img_x, int64_t img_y, double Lx, double D)
{
    return bd_unwrap(x, img_x, Lx) + (double)img_y * D;
}

/* A pair with separation dr (q - p, already through the nearest image on each axis) and
 * raw y separation dy_raw: the y image ky (-1, 0, 1) of q that touches p, dr[0] then
 * moved to that image's x (displaced by ky delta, nearest along x).  q's image moves with
 * v_x + ky u. */
static inline int bd_le_image(double *dr, double dy_raw, double Ly, double Lx, double delta)
{
    const int ky = dy_raw > 0.5 * Ly ? -1 : dy_raw < -0.5 * Ly ? 1 : 0;
    if (ky) dr[0] = bd_nearest(dr[0] + (double)ky * delta, Lx);
    return ky;
}

#endif
