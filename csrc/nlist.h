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
 * In a sheared box (Lees-Edwards, boundary.h) the gas flows, u_x = rate (y - y_c), and
 * the images across the y faces slide along x at u = rate L_y.  Shells fixed in the box
 * would be left at the flow's speed, so here they move with it (le_cells.h has the code,
 * le_nlist.h the events):
 *  - A list centre c_i, i's position at its build t_b,i, moves with the flow at its own
 *    y, c_i(t) = c_i + w_i (t - t_b,i) e_x, w_i = rate (c_i,y - y_c); i leaves its shell
 *    when |r_i(t) - c_i(t)| reaches delta (flight.h fl_exit_time with v - w_i e_x), or
 *    when its life ends: a strain |rate| (t - t_b,i) of GR_NL_STRAIN or less (below),
 *    and no more than a centre drift of L_x / 4 - delta.  The images of a centre across a
 *    y face move with the flow there too: the flow at y + L_y is the flow at y plus u.
 *  - Two centres' separation d changes only along x, at rate d_y: over the life, from
 *    d(t_b) to d(t_b) + s d_y e_x with s up to the strain of a life.  So i lists every j
 *    (through every image) whose separation comes within r_i + r_j + 2 delta for some s
 *    in that range: |d_x + s d_y| reaches its least at an end or at 0 (the sweep).
 *  - Why no pair is missed.  Whether i and j are listed was decided at the later of their
 *    builds, t_b, from the centres then and their motion with the flow, which is exact
 *    (d is linear in t).  Until either list ends (within a life of t_b) an unlisted
 *    pair has |d(t)| >= sigma + 2 delta, and each particle is within delta of its
 *    centre: no contact, as without shear.
 *  - Entries through a y face store their y (and z) image only; the x image is the
 *    nearest one at each use, displaced by s_y delta(t) (bd_le_image, as the pair
 *    collision finds it), and the pair's relative velocity gains s_y u.  No stored image
 *    follows delta's wraps at L_x, and delta comes from the absolute time as everywhere.
 *    Entries within the box store their x image as found at the build: it stays the
 *    touching one, below.
 *  - Why the images stay right.  Over a strain s a separation's length changes by a
 *    factor e^(s/2) at most (|d/dt |d|| <= |rate| |d| / 2).  A scan at t_s predicts a
 *    contact at t_c with both lists alive between, so the touching image's centres were
 *    within e^(s/2) (sigma + 2 delta) at t_s and the particles within that plus 2 delta:
 *    the build requires e^(s/2) (sigma + 2 delta) + 2 delta < 0.49 L on every axis for
 *    the strain s of a life (nlist.c gr_nlist_shear_strain; a box too small for strain
 *    0.1 takes cells), so that image is the nearest, and the one stored at the build
 *    (within sigma + 2 delta then) is the touching one.  The drift bound keeps positions
 *    within L_x / 4 of the box, so one step of bd_nearest finds the nearest image.
 * Rounding: the centres carried by the flow and delta(t) carry the time's rounding times
 * the flow's speed; the shells are 2^-48 (|D(t_b)| + L_x) smaller for it besides the
 * plain shell's hair (nlist.c). */
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
#define GR_NL_TILT 0.1
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
    double *expiry;   /* 2 n: each list's end of life and shell radius (le_expiry) */
    int8_t *lap;      /* n: the box lengths from a centre's filed x to the flow's (le_cells.h) */
    int32_t *blocks;  /* GR_LE_BLOCK a cell: its count, its first centres (le_cells.h) */
    double lx;        /* L_x */
    double rate;      /* the shear rate: a centre moves with the flow rate (y - yc) */
    double yc;        /* the box's middle in y, where the flow is at rest */
    double r_max;     /* the largest radius */
    double life;      /* a list's longest life */
    double drift;     /* the farthest the flow may carry a centre along x */
    double tref;      /* the time the centres are filed at (le_cells.h) */
    double dref;      /* the images' offset delta at tref (bd_le_offset) */
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
