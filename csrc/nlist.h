/* nlist.h -- neighbour lists (Verlet lists as in Smallenburg's EDMD), the engine's mode
 * for dense gases.
 *
 * In a dense gas a scan's 27 cells hold ~25 particles, of which only the ~8 nearest can
 * be hit before long.  Particle i lists everyone whose list centre lies within
 * r_i + r_j + 2 delta of its own, the centre being i's position when its list was last
 * built; leaving the sphere of radius delta about it is i's structural event (a shell
 * exit, in place of a cell crossing), which rebuilds i's list from the cells (that hold
 * centres, not positions) and mends its neighbours' lists, which stay symmetric.  Two
 * particles each within delta of their centres can only touch if listed, so predictions
 * scan the list: contiguous indices whose records load in parallel, where a cell's
 * linked list is a chain of dependent loads.
 *
 * Rows of `cap` entries, doubled when one overflows (rarely with the automatic shell of
 * 0.25 diameters: a close-packed crystal has 18 neighbours within 1.5 diameters in 3D, 6
 * in 2D; a wide particle among small ones has more).  An entry is (j << GR_NL_BITS) |
 * image code: the shift that brings j next to i stays the same until one of them
 * rebuilds, so scans need no nearest-image arithmetic.  List lengths live in the
 * scheduling state (schedstate.h, `nn`), on the line an event loads anyway.
 *
 * In a sheared box (Lees-Edwards, boundary.h) the images across the y faces slide along
 * x at u = (shear rate) L_y, so a list built through such a face goes stale with no
 * event of either particle.  The lists stay exact so (lees_edwards.h has the code):
 *  - An entry through a y face stores its y (and z) image only; its x image is the
 *    nearest one at each use, displaced by s_y delta(t) (bd_le_image, as the pair
 *    collision finds it), and the pair's relative velocity gains s_y u.  No stored image
 *    has to follow delta's wraps at L_x, and delta comes from the absolute time as
 *    everywhere (no offset per build accumulating rounding over a long run).
 *  - Each particle whose centre lies in a cell next to a y face when its list is built
 *    (the only ones whose reach, r_i + r_j + 2 delta <= a cell's width, can cross that
 *    face) gets a shell that shrinks: it leaves when |r_i(t) - c_i| + (|u|/2)(t - t_b,i)
 *    reaches delta (flight.h fl_shrink_exit_time; t_b,i its build time, in `built`, +inf
 *    for the plain shell of the others).
 *  - Why no pair is missed.  Whether i and j are listed was decided at the later of
 *    their builds, t_b = max(t_b,i, t_b,j), with the centres' distance through every
 *    image then.  An unlisted pair through a y face had it >= r_i + r_j + 2 delta; since
 *    then that image drifted by |u| (t - t_b) along x, so
 *      |r_j + S(t) - r_i| >= sigma + 2 delta - |r_i - c_i| - |r_j - c_j| - |u| (t - t_b)
 *    and with both shells alive |r_i - c_i| + |r_j - c_j| + (|u|/2)(2t - t_b,i - t_b,j)
 *    <= 2 delta, where (|u|/2)(2t - t_b,i - t_b,j) >= |u| (t - t_b): no contact.  If
 *    either centre is not in an edge row it lies a cell width (>= sigma + 2 delta) from
 *    the face, and the y separation alone keeps them apart, as without shear.
 *  - Why the nearest x image at a scan is the one that touches: a scan at t_s predicts a
 *    contact at t_c with no event of i or j between (else that event scans again), so
 *    both shells live over [t_s, t_c] and |dr_i| + |dr_j| + |u| (t_c - t_s) <= 4 delta
 *    (each particle moves at most 2 delta less its shrink); the touching image is then
 *    within sigma + 4 delta < L_x / 2 along x at t_s (build.c: L > 2 (sigma + 4 delta)),
 *    nearer than any other.
 * Rounding: delta(t) carries the time's rounding times u (boundary.h); the shrinking
 * shells start 2^-48 (|D(t_b)| + L_x) early besides the plain shell's hair (nlist.c). */
#ifndef GR_NLIST_H
#define GR_NLIST_H

#include <math.h>
#include <stdint.h>

#include "common.h"
#include "schedstate.h"

#define GR_NL_CAP_MAX 16384
#define GR_NL_CAP_START(dim) ((dim) == 3 ? 32 : 16) /* rows' capacity before any growth */
#define GR_NL_BITS 5
/* a sheared box's centres are filed anew when the strain since their filing time passes
 * this, as |rate (t - t_ref)| (le_cells.h) */
#define GR_NL_TILT 0.05
/* a sheared box's list lives at most this strain, |rate| t (nlist.h) */
#ifndef GR_NL_STRAIN
#define GR_NL_STRAIN 0.4
#endif
#define GR_NL_CODE_MASK ((1 << GR_NL_BITS) - 1)
/* the image code in the low GR_NL_BITS bits leaves list mode n < 2^26 */
#define GR_NL_MAX_N ((int64_t)1 << (31 - GR_NL_BITS))

typedef struct {
    double shell;     /* delta, absolute; 0: no lists (cell-crossing mode) */
    double exit2;     /* squared distance from the centre that ends a list's life */
    double *centre;   /* n * (dim + 1): each list centre and the particle's radius */
    int32_t *rows;    /* n * cap: i's neighbours from rows[i * cap] on, sched[i].nn of them */
    int32_t cap;
    int32_t *near;    /* n: room for a rebuild's new neighbours */
    uint8_t *mark;    /* n, all 0 but during a shell exit's relinking (search.h) */
    int broken;       /* a list could not grow: lists are incomplete, no more events */
    /* sheared boxes only (le_cells.h, le_nlist.h): */
    double *built;    /* n (else NULL): each list's build time */
    int8_t *lap;      /* n: the box lengths from a centre's filed x to the flow's (le_cells.h) */
    double lx;        /* L_x */
    double rate;      /* the shear rate: a centre moves with the flow rate (y - yc) */
    double yc;        /* the box's middle in y, where the flow is at rest */
    double r_max;     /* the largest radius */
    double life;      /* a list's longest life */
    double drift;     /* the farthest the flow may carry a centre along x */
    double tref;      /* the time the centres are filed at (le_cells.h) */
    double span;      /* filed anew once the time passes tref + span */
    double img[32][4];/* image code -> shift, code = sum over axes of (s_a + 1) 3^a; the
                       * fourth column 0, for loads of four (scan_avx2.h) */
} gr_nlist;

/* The image code of no shift on any axis (every s_a = 0): the middle of the 3^dim. */
#define GR_NL_CODE_NONE(dim) ((dim) == 3 ? 13 : 4)

/* The image code of a shift (each axis -L, 0 or +L, as cells.h gives them). */
static inline int32_t nl_code(int dim, const double *shift)
{
    int32_t code = 0;
    for (int a = dim - 1; a >= 0; a--) code = 3 * code + (shift[a] > 0.0) - (shift[a] < 0.0) + 1;
    return code;
}

/* Lists with a shell delta (> 0) for n particles in a box of sides L.  GR_OK or
 * GR_ERR_NOMEM. */
int gr_nlist_init(gr_nlist *nl, int dim, int32_t n, double shell, const double *L);
void gr_nlist_free(gr_nlist *nl);
/* The longest life of a sheared box's list as a shear strain |rate| t (nlist.h), for a
 * box of sides L, the largest diameter sigma_max and a shell delta; <= 0 if the box is
 * too small for lists under shear. */
double gr_nlist_shear_strain(int dim, const double *L, double sigma_max, double shell);
/* A sheared box's lists (le_cells.h): build times and the flow.  GR_OK or GR_ERR_NOMEM. */
int gr_nlist_shear(gr_nlist *nl, int dim, int32_t n, double rate, const double *lo,
                   const double *L, double sigma_max);
/* Double the rows' capacity; on failure the lists are marked broken.  GR_OK or
 * GR_ERR_NOMEM. */
int gr_nlist_grow(gr_nlist *nl, int32_t n, const gr_sched *sched);

static inline int32_t *nl_row(const gr_nlist *nl, int32_t i)
{
    return nl->rows + (size_t)i * nl->cap;
}

/* List i and j as neighbours of each other, j seen from i through image `code`.
 * GR_OK or GR_ERR_NOMEM (a row could not grow). */
static inline int nl_link(gr_nlist *nl, int dim, int32_t n, gr_sched *sched, int32_t i,
                          int32_t j, int32_t code)
{
    if (sched[i].nn == nl->cap || sched[j].nn == nl->cap) {
        int status = gr_nlist_grow(nl, n, sched);
        if (status != GR_OK) return status;
    }
    const int32_t opposite = 2 * GR_NL_CODE_NONE(dim) - code; /* every s_a negated */
    nl_row(nl, i)[sched[i].nn++] = (j << GR_NL_BITS) | code;
    nl_row(nl, j)[sched[j].nn++] = (i << GR_NL_BITS) | opposite;
    return GR_OK;
}

/* Take i off j's list (order within a list does not matter). */
static inline void nl_unlink(gr_nlist *nl, gr_sched *sched, int32_t j, int32_t i)
{
    int32_t *row = nl_row(nl, j);
    const int last = sched[j].nn - 1;
    for (int k = 0; k <= last; k++)
        if (row[k] >> GR_NL_BITS == i) {
            row[k] = row[last];
            sched[j].nn--;
            return;
        }
}

/* When a particle leaves its shell: fl_exit_time (flight.h), a matter of its motion. */

#endif
