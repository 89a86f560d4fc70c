/* engine.h -- the inside of a gr_edmd, shared by the engine's C files (not by the
 * binding, which sees edmd.h only).
 *
 * A particle record is P[i*GR_STRIDE(dim) ...] = x[dim] v[dim] t r: position at the particle's
 * own time t, velocity, radius.  Times are absolute.  Functions take the dimension as
 * an argument `dim`; the event loop (edmd.c) is compiled once for dim = 2 and once for
 * dim = 3 (advance_2d, advance_3d), and the helpers it calls are inlined or cloned by
 * the compiler with that constant, so a 2D scene never pays for a third dimension. */
#ifndef GR_ENGINE_H
#define GR_ENGINE_H

#include <stddef.h>
#include <stdint.h>

#include "big.h"
#include "boundary.h"
#include "calendar.h"
#include "cells.h"
#include "edmd.h"
#include "flight.h"
#include "nlist.h"
#include "schedstate.h"

/* renumbering: see renumber.c */
typedef struct {
    int32_t *id_of;       /* the caller's index of each internal particle */
    void *scratch;        /* room for n records or n scheduling states, NULL: never */
    int64_t next;         /* renumber when the event count reaches this */
} gr_renumbering;

struct gr_edmd {
    gr_edmd_config cfg;
    int dim;
    int32_t n;
    double L[3];
    double *P;            /* n records (rec), 64-byte aligned */
    double *mass;
    double *spin;         /* rough particles' angular velocities (rule.h): n (2D) or n * 3
                           * (3D) doubles, in the particles' internal order; NULL: smooth */
    int64_t *image;       /* n * dim periodic image counters */
    gr_sched *sched;      /* n: each particle's scheduling state */
    gr_cq queue;
    gr_cells cells;       /* with lists: the cells of the list centres */
    gr_big big;           /* none with lists */
    gr_nlist nl;          /* nl.shell == 0: cell-crossing mode */
    gr_renumbering order;
    int lookahead;        /* prefetch three events ahead (cells, large grid) */
    int32_t foreseen[2];  /* the particles whose heads and state were asked for ahead */
    int32_t ahead_cells[27], ahead_m; /* the occupied cells foreseen[0]'s event scans */

    /* time and counters */
    double t, eps_t;
    double t_prev_event;
    int64_t same_instant;
    int64_t events, pair, wall, invalid, elastic_tc;
    int64_t crossings;    /* cell crossings */
    int64_t shell_exits;  /* list mode: shell exits, each rebuilding one list */
    double virial, wall_impulse;
    double kinetic;       /* total kinetic energy, updated by differences at each collision */
    double kinetic_time;  /* integral of the total kinetic energy over time, for the pressure */
    int64_t law_clamped;  /* collisions past a viscoelastic law's range (restitution.h) */
    /* Lees-Edwards (boundary.h, lees_edwards.h): le = 1 if sheared; the images' speed
     * u = shear_rate L_y; the work they did (counters' shear_work) */
    int le;
    double le_u;
    double shear_work;
    /* the stress tensor (stress.h), kept with cfg.stress only: d x d, row-major */
    double st_coll[9];     /* sum over pair collisions of r_a dp_b */
    double st_kin[9];      /* the kinetic tensor sum m v_a v_b now */
    double st_kin_time[9]; /* its integral over time up to stress_t */
    double stress_t;
    /* the random driving force (drive.c): the time of kick number `kicks`, the kicks done,
     * the kinetic energy they gave */
    double drive_next;
    int64_t kicks;
    double drive_energy;
    double wall_work;      /* vibrating wall (vibwall.h): the work it did on the particles */
    double collision_loss; /* vibrating wall: the energy collisions dissipated */
    /* gravity only (flight.h, fl_kinetic_integral): the total momentum at time t, which
     * the kinetic energy's growth in flight needs, and the total mass */
    double momentum[3];
    double mass_total;
};

/* Consecutive collisions of one particle, each within eps_t of the previous, that are
 * taken as inelastic collapse.  A gas never comes near this by chance (each such
 * collision has a probability of order 1e-9).  A fast collapse completes in floating
 * point within few collisions: three disks in a line with xi = 0.05 (< 7 - 4 sqrt 3)
 * make 46 collisions, of which only 16 to 19 in a row fall within eps_t, so the
 * threshold must stay well below that. */
#define GR_COLLAPSE_STREAK 10
#define GR_STR(x) #x
#define GR_XSTR(x) GR_STR(x)

/* Prefetching: at large N the particle an event touches is a cache miss in every
 * per-particle array; asking for them one event ahead (and for a pair's partner before
 * the first of them is used) overlaps those misses with useful work.  A hint only:
 * compilers without the builtin lose speed, not correctness. */
#if defined(__GNUC__) || defined(__clang__)
#define GR_PREFETCH(p) __builtin_prefetch(p)
#else
#define GR_PREFETCH(p) ((void)(p))
#endif

/* spin components per particle: 1 in 2D (along z), 3 in 3D */
#define GR_SPIN_DIM(dim) ((dim) == 2 ? 1 : 3)

/* the parts of record p, for dimension dim */
#define VEL(p, dim) ((p) + (dim))
#define TIME(p, dim) ((p)[2 * (dim)])
#define RAD(p, dim) ((p)[2 * (dim) + 1])

/* doubles per particle record: x[dim] v[dim] t r, padded to 8 (64 bytes, one cache line:
 * a 2D record of 6 doubles would straddle two lines every other time) */
#define GR_STRIDE(dim) ((2 * (dim) + 2 + 7) / 8 * 8)

/* Particle i's record.  With dim a constant of the loop the stride is too: the address
 * is a shift, not a multiplication waiting on a load of the stride (in the scans, that
 * address is on the path from the list entry to the candidate's data). */
static inline double *rec(const gr_edmd *s, int dim, int32_t i)
{
    return s->P + (size_t)i * GR_STRIDE(dim);
}

/* The caller's index of internal particle i (negative codes pass through). */
static inline int64_t uid(const gr_edmd *s, int32_t i) { return i < 0 ? -1 : s->order.id_of[i]; }

/* The dynamics of system s (flight.h): gravity when the config's acceleration is not
 * zero, else constant velocity; gr_edmd_advance chooses its loop from it. */
static inline int dynamics_of(const gr_edmd *s)
{
    const double *g = s->cfg.gravity;
    return g[0] != 0.0 || g[1] != 0.0 || g[2] != 0.0 ? GR_FLIGHT_GRAVITY : GR_FLIGHT_LINEAR;
}

/* Move record p of system s in free flight (flight.h) to time t. */
static inline void move(const gr_edmd *s, int dyn, int dim, double *p, double t)
{
    fl_move(dyn, dim, p, VEL(p, dim), s->cfg.gravity, &TIME(p, dim), t);
}

/* The total kinetic energy summed from the velocities: the event loop's (with its
 * constant dim, a loop of a few instructions a particle) and the counters' give the same
 * bits, so a run stopped on energy reads at most its target in the counters.  Records
 * hold the velocities at each particle's own clock: right for constant velocity, where
 * they do not change in flight; under gravity they are brought to s->t first, and the
 * total momentum at s->t is summed into momentum[dim] (if not NULL) on the way. */
static GR_NOINLINE double kinetic_total_gravity(const gr_edmd *s, int dim, double *momentum)
{
    double k = 0.0, mom[3] = {0.0, 0.0, 0.0};
    for (int32_t i = 0; i < s->n; i++) {
        const double *p = rec(s, dim, i), dt = s->t - TIME(p, dim);
        double v[3];
        for (int a = 0; a < dim; a++) {
            v[a] = fl_vel_at(GR_FLIGHT_GRAVITY, VEL(p, dim)[a], s->cfg.gravity[a], dt);
            mom[a] += s->mass[i] * v[a];
        }
        k += fl_kinetic(GR_FLIGHT_GRAVITY, dim, s->mass[i], v);
    }
    if (momentum)
        for (int a = 0; a < dim; a++) momentum[a] = mom[a];
    return k;
}

static inline double kinetic_total(const gr_edmd *s, int dyn, int dim, double *momentum)
{
    double k = 0.0;
    if (dyn == GR_FLIGHT_GRAVITY) return kinetic_total_gravity(s, dim, momentum);
    (void)momentum;
    for (int32_t i = 0; i < s->n; i++)
        k += fl_kinetic(dyn, dim, s->mass[i], VEL(rec(s, dim, i), dim));
    return k;
}

/* Validation of a configuration (validate.c): arguments, radii, masses, finiteness, the
 * box and who lies outside it.  GR_OK or an error with err filled. */
int gr_validate_config(const gr_edmd_config *cfg, const double *pos, const double *vel,
                       const double *radius, const double *mass, gr_error *err);
/* The first overlap among n particles (positions pos[i * pstride ...], radii
 * radius[i * rstride]) in a box of sides L: big ones against everyone, the others
 * through grid g, whose lists must hold every particle that is not big.  sheared: NULL,
 * or a Lees-Edwards box's image offset (boundary.h; no big particles then).  GR_OK or
 * GR_ERR_OVERLAP with err filled. */
int gr_find_overlap(int dim, int32_t n, const double *pos, size_t pstride,
                    const double *radius, size_t rstride, int periodic, const double *L,
                    const gr_cells *g, const gr_big *b, const double *sheared, gr_error *err);

/* Renumber the particles in the order of their cells (renumber.c).  GR_OK or
 * GR_ERR_NOMEM (nothing changed then). */
int gr_renumber(gr_edmd *s);
/* Large systems renumber every GR_RENUMBER_EVENTS_PER_N * N events; small ones (below
 * GR_RENUMBER_MIN_N) fit in the cache anyway and never do. */
#define GR_RENUMBER_MIN_N 4096
#define GR_RENUMBER_EVENTS_PER_N 16

/* Write sample smp->next, the state at time ts, and advance smp->next (sample.c). */
void gr_write_sample(const gr_edmd *s, gr_edmd_samples *smp, double ts);

/* The first predictions of every particle (edmd.c); lists and cells must be built. */
int gr_predict_all(gr_edmd *s, gr_error *err);
/* Predict particle i anew after its velocity changed outside a collision (edmd.c); its
 * clock must be the current time. */
void gr_predict_one(gr_edmd *s, int32_t i);
/* The constant-velocity loop, chosen as gr_edmd_advance chooses it (edmd.c), without the
 * driving force: drive.c runs it between kicks. */
int gr_edmd_advance_plain(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err);

/* Gravity's loop and first predictions (edmd.c compiled again as edmd_gravity.c), which
 * gr_edmd_advance and gr_predict_all call for a system under gravity. */
int gr_edmd_advance_gravity(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                            gr_error *err);
int gr_predict_all_gravity(gr_edmd *s, gr_error *err);
void gr_predict_one_gravity(gr_edmd *s, int32_t i);

/* The loops of rough particles and of a vibrating wall (edmd.c compiled again as
 * edmd_extra.c), which gr_edmd_advance calls for such a system without gravity. */
int gr_edmd_advance_extra(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err);
/* Rough particles beside a vibrating wall (edmd_rough_vib.c) and under gravity, with or
 * without a vibrating floor (edmd_gravity_rough.c), each edmd.c compiled again: called by
 * gr_edmd_advance_extra and gr_edmd_advance_gravity for a system with spins. */
int gr_edmd_advance_vib_rough(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                              gr_error *err);
int gr_edmd_advance_gravity_rough(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                                  gr_error *err);
/* The list scan's kernel, set once by gr_scan_init (edmd.c): 1 AVX2, 0 plain. */
extern int gr_scan_avx2;

#endif
