/* edmd.c -- the event loop, then the events it processes, then the predictions.
 *
 * Read top to bottom: advance() pops the earliest particle from the queue and does its
 * event -- a pair collision, a wall collision, a cell crossing (cells.h) or a shell
 * exit (nlist.h) -- and every event ends in predict() for the particles it changed,
 * whose pair searches are in search.h.
 *
 * Why the per-event cost does not grow with N:
 *  - every particle carries its own clock: its record holds the position at time t_i
 *    and is advanced only when an event touches it;
 *  - a particle looks for partners in its own and the adjacent cells only (cells.h), or
 *    in its neighbour list (nlist.h); big particles stay out of the cells (big.h);
 *  - each particle keeps one predicted collision (pair or wall) and one cell crossing or
 *    shell exit; the queue holds the earlier of the two.  A predicted pair collision
 *    remembers the partner's collision counter and is found stale when popped if the
 *    partner collided since (lazy invalidation) -- then only that particle is rescanned;
 *  - the queue is a calendar queue (calendar.c): O(1) per key change, where a heap's
 *    O(log N) sift is a chain of cache misses at large N;
 *  - at large N what remains is memory latency: particles are renumbered in cell order
 *    now and then (renumber.c), the next event's particle and a pair's partner are
 *    prefetched (with a grid out of cache, three events ahead: prefetch_ahead), and the
 *    big arrays sit on huge pages where the OS offers them.
 * Invariant: for every pair of particles within reach (adjacent cells; a big particle's
 * block; a neighbour list), the earliest collision on their current straight lines is no
 * earlier than the queue key of one of the two. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "drive.h"
#include "engine.h"
#include "rule.h"
#include "search.h"
#include "stress.h"
#include "vibwall.h"

/* The rough units are their parents compiled with rough loops (see the units' comment
 * above advance_2d): edmd_gravity_rough.c gravity's unit, edmd_rough_vib.c the extra one. */
#ifdef GR_EDMD_GRAVITY_ROUGH_UNIT
#define GR_EDMD_GRAVITY_UNIT 1
#endif
#ifdef GR_EDMD_VIB_ROUGH_UNIT
#define GR_EDMD_EXTRA_UNIT 1
#endif

/* Everything an event of particle i is about to read or write, requested at once.  A
 * macro, not a function: GCC takes a function that only prefetches for one without
 * effects and deletes the calls (seen with GCC 12 at -O3: none of these was emitted). */
#define PREFETCH_PARTICLE(s, dim, i)                                                    \
    do {                                                                                \
        GR_PREFETCH(rec((s), (dim), (i)));                                              \
        GR_PREFETCH(&(s)->sched[(i)]);                                                  \
        GR_PREFETCH(&(s)->cells.next[(i)]);                                             \
        GR_CQ_PREFETCH(&(s)->queue, (i));                                               \
        if ((s)->nl.shell > 0.0) GR_PREFETCH(nl_row(&(s)->nl, (i)));                    \
    } while (0)

/* Where the cell grid is out of cache (s->lookahead), a pipeline over the next three
 * events, run at each event: the third from now has its particle's state asked for; the
 * second, whose state was asked for an event ago, the heads of the cells its event will
 * scan (and a partner's state); the next one, whose heads were asked for an event ago,
 * the first particle in each of those cells.  Each stage reads only what the one before
 * asked for, and only if that event was foreseen then (the queue's guess is right ~97 %
 * of the time), so a wrong guess costs a wasted request, not a wait.  The chain of
 * misses in a scan -- cell head, then the particle it names -- is then mostly paid in
 * the shadow of earlier events (N = 1e6: 0.81-0.87 of the time per event without). */
static GR_ALWAYS_INLINE void prefetch_ahead(gr_edmd *s, int dim)
{
    int32_t ahead[GR_CQ_AHEAD];
    gr_cq_ahead(&s->queue, ahead);
    if (ahead[0] >= 0 && ahead[0] == s->foreseen[0]) prefetch_firsts(s, dim);
    s->ahead_m = 0;
    if (ahead[1] >= 0 && ahead[1] == s->foreseen[1]) {
        prefetch_heads(s, dim, ahead[1]);
        const gr_sched *f = &s->sched[ahead[1]];
        if (f->t_coll <= f->t_cross && f->partner >= 0) PREFETCH_PARTICLE(s, dim, f->partner);
    }
    if (ahead[2] >= 0) PREFETCH_PARTICLE(s, dim, ahead[2]);
    s->foreseen[0] = ahead[1];
    s->foreseen[1] = ahead[2];
}

static void set_clock(gr_edmd *s, int dyn, double t);
static double next_sample(const gr_edmd_samples *smp);

/* Whether this unit compiles the rough rule (rule.h) at all: not the plain unit, whose
 * do_pair_sheared, a function with a run-time `laws`, would otherwise carry its code. */
#if defined(GR_EDMD_GRAVITY_UNIT) || defined(GR_EDMD_EXTRA_UNIT)
#define GR_UNIT_ROUGH 1
#else
#define GR_UNIT_ROUGH 0
#endif
/* The vibrating wall's loops' rule: the law rule, or in the rough units the rough one. */
#if defined(GR_EDMD_GRAVITY_ROUGH_UNIT) || defined(GR_EDMD_VIB_ROUGH_UNIT)
#define GR_VIB_LAWS GR_RULE_ROUGH
#else
#define GR_VIB_LAWS 1
#endif

/* The collision count 2 * pair + wall at which s->kinetic is next summed anew: the next
 * multiple of GR_KINETIC_RESUM * n above the present count. */
#define GR_KINETIC_RESUM 16
static double next_resum(const gr_edmd *s)
{
    const int64_t every = GR_KINETIC_RESUM * (int64_t)s->n;
    return (double)((2 * s->pair + s->wall) / every + 1) * (double)every;
}

/* The events are inlined into each of the four loops (as GCC did by itself for the two
 * loops before laws came): each loop then holds its own copy, compiled for its dim and
 * laws, and the constant-restitution loops execute exactly the instructions they did. */
static GR_ALWAYS_INLINE int do_pair(gr_edmd *s, int dyn, int dim, int laws, int32_t i, int32_t j,
                                    double t, gr_error *err);
static GR_ALWAYS_INLINE int do_wall(gr_edmd *s, int dyn, int dim, int laws, int32_t i, int wall,
                                    double t, gr_error *err);
static GR_ALWAYS_INLINE void do_cross(gr_edmd *s, int dyn, int dim, int32_t i, double t);
static GR_ALWAYS_INLINE int do_shell_exit(gr_edmd *s, int dyn, int dim, int32_t i, double t,
                                          gr_error *err);
static void predict(gr_edmd *s, int dyn, int dim, int32_t i);
#if defined(GR_EDMD_GRAVITY_UNIT) || defined(GR_EDMD_EXTRA_UNIT)
static int advance_vib(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                       gr_error *err);
#endif
static int do_pair_sheared(gr_edmd *s, int dyn, int dim, int laws, int32_t i, int32_t j,
                           double t, gr_error *err);
static void do_face_sheared(gr_edmd *s, int dyn, int dim, int32_t i, double t, int up,
                            int32_t old);
static void le_face_moves(gr_edmd *s, int dyn, int dim, int32_t i, double t, int up);
static int le_list_reenter(gr_edmd *s, int dyn, int dim, int32_t i, double t);
static GR_ALWAYS_INLINE int do_vibwall(gr_edmd *s, int dyn, int dim, int laws, int32_t i,
                                       double t, gr_error *err);

/* The loop, for dynamics dyn (flight.h: how particles move between events), dimension
 * dim and laws = 0 (constant restitution), 1 (a restitution law, restitution.h) or
 * GR_RULE_ROUGH (rough particles, rule.h),
 * constants in each of the four advance_* below: a constant-xi run executes the loop
 * compiled without any law code, not a test per collision, and each dynamics gets its
 * own loop the same way (constant velocity, GR_FLIGHT_LINEAR, and gravity: a new one
 * adds its advance_* and its choice in gr_edmd_advance, and no line here). */
static GR_ALWAYS_INLINE int advance(gr_edmd *s, const int dyn, const int dim, const int laws,
                                    const gr_edmd_stop *stop, gr_edmd_samples *smp,
                                    gr_error *err, const int vib)
{
    const double t_stop = stop->t_stop;
    const int64_t n = s->n;
    const double collisions = stop->collisions_per_particle * (double)n;
    /* s->kinetic, updated by differences at each collision, carries rounding of order
     * 1e-16 of the largest energy it has held since it was last summed from the
     * velocities: in a gas cooled by many orders of magnitude (a fast particle between
     * absorbing walls) that error exceeds the energy itself.  So it is summed anew
     * every GR_KINETIC_RESUM collisions a particle (at fixed collision counts: the same
     * whatever the calls and checkpoints; one particle's energy summed per
     * GR_KINETIC_RESUM collisions), and whenever it reaches the energy test's gate: the
     * target, where the run then stops on the fresh sum alone, or without one any
     * negative value (not 0: a gas at rest would sum itself at every collision). */
    const double kinetic =
        stop->energy ? stop->kinetic_energy * (double)n : nextafter(0.0, -1.0);
    double resum = fmin(collisions, next_resum(s));
    /* events at one instant beyond this are a pile-up (every particle crossing a cell
     * wall at once, as a moving lattice does, is still well below it) */
    const int64_t pileup = 16 * n + 1000;
    /* Before this time no sample is due and the run does not stop for time: most events
     * then need one comparison for both. */
    double t_gate = fmin(next_sample(smp), t_stop);
    /* The collision and energy criteria change only with a collision; they are tested
     * after the first event of the call and after every collision. */
    int check = 1;
    for (int64_t k = 0;; k++) {
        if (k >= stop->max_events) return GR_STOP_BUDGET;
        if (s->order.scratch && s->events >= s->order.next) {
            int status = gr_renumber(s);
            if (status != GR_OK) return status;
        }
        double te;
        const int32_t i = gr_cq_top(&s->queue, &te);
        if (te != te) {
            gr_error_set(err, GR_ERR_NONFINITE, uid(s, i), -1, s->t, te, "an event time");
            return GR_ERR_NONFINITE;
        }
        if (te >= t_gate) {
            while (smp && smp->next < smp->count && smp->times[smp->next] <= te &&
                   smp->times[smp->next] <= t_stop) {
                double ts = smp->times[smp->next];
                gr_write_sample(s, smp, ts);
                set_clock(s, dyn, ts);
            }
            if (te > t_stop) {
                set_clock(s, dyn, t_stop);
                return GR_STOP_TIME;
            }
            if (te == INFINITY) return GR_STOP_IDLE;
            t_gate = fmin(next_sample(smp), t_stop);
        }
        if (te <= s->t_prev_event) {
            if (++s->same_instant > pileup) {
                gr_error_set(err, GR_ERR_COLLAPSE, uid(s, i), uid(s, s->sched[i].partner), te, (double)pileup,
                             "events pile up at one instant");
                return GR_ERR_COLLAPSE;
            }
        } else {
            s->same_instant = 0;
            s->t_prev_event = te;
        }
        set_clock(s, dyn, te);
        s->events++;
        gr_sched *e = &s->sched[i];
        if (s->lookahead) prefetch_ahead(s, dim);
        if (s->n >= GR_RENUMBER_MIN_N) { /* below, everything sits in L2 */
            int32_t h = gr_cq_hint(&s->queue);
            if (h >= 0) PREFETCH_PARTICLE(s, dim, h);
            if (e->t_coll <= e->t_cross && e->partner >= 0) PREFETCH_PARTICLE(s, dim, e->partner);
        }
        int status = GR_OK;
        if (e->t_cross < e->t_coll) {
            if (s->nl.shell > 0.0) status = do_shell_exit(s, dyn, dim, i, te, err);
            else do_cross(s, dyn, dim, i, te);
        } else if (e->partner >= 0) {
            if (s->sched[e->partner].count != e->pcount) { /* partner collided since: stale */
                s->invalid++;
                move(s, dyn, dim, rec(s, dim, i), te);
                predict(s, dyn, dim, i);
                continue;
            }
            /* vibwall.h's bookkeeping (the rough rule books its own loss: do_pair) */
            const int books = vib && !GR_RULE_IS_ROUGH(laws);
            const double k0 = books ? s->kinetic : 0.0;
            status = do_pair(s, dyn, dim, laws, i, e->partner, te, err);
            if (books) s->collision_loss += k0 - s->kinetic;
            check = 1;
        } else if (vib && -2 - e->partner == 2 * s->cfg.vib.axis + s->cfg.vib.side) {
            status = do_vibwall(s, dyn, dim, laws, i, te, err);
            check = 1;
        } else {
            const double k0 = vib ? s->kinetic : 0.0;
            status = do_wall(s, dyn, dim, laws, i, -2 - e->partner, te, err);
            if (vib) s->collision_loss += k0 - s->kinetic;
            check = 1;
        }
        if (status != GR_OK) return status;
        if (check) {
            check = 0;
            const double count = (double)(2 * s->pair + s->wall);
            if (count >= resum || s->kinetic <= kinetic) { /* rarely: resum <= collisions */
                if (count >= collisions) return GR_STOP_COLLISIONS;
                s->kinetic = kinetic_total(s, dyn, dim, s->momentum);
                if (s->cfg.stress) { /* the kinetic tensor too (stress.h) */
                    stress_sync(s, dim, s->t);
                    stress_resum(s, dim);
                }
                if (count >= resum) resum = fmin(collisions, next_resum(s));
                if (stop->energy && s->kinetic <= kinetic) return GR_STOP_ENERGY;
            }
        }
    }
}

/* This file is compiled five times: as itself, the loops of constant velocity with
 * smooth particles and fixed walls (the plain loop's unit); by edmd_gravity.c
 * (GR_EDMD_GRAVITY_UNIT) for gravity's loops; by edmd_extra.c (GR_EDMD_EXTRA_UNIT) for
 * the loops of rough particles and of a vibrating wall; and by edmd_gravity_rough.c and
 * edmd_rough_vib.c for rough particles under gravity and beside a vibrating wall.  Apart,
 * the compiler's choices of what to inline and clone for the plain loop are those it made
 * before the others came: in one unit, the search functions' clones for every loop outgrew
 * its limits and the plain loop ran 7-13 % more instructions an event.  The same held
 * among the others: the rough loops under gravity and beside the wall in the gravity and
 * extra units cost the loops there 5-9 % more instructions a pair collision. */
#if !defined(GR_EDMD_GRAVITY_UNIT) && !defined(GR_EDMD_EXTRA_UNIT)
static int advance_2d(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err)
{
    return advance(s, GR_FLIGHT_LINEAR, 2, 0, stop, smp, err, 0);
}

static int advance_3d(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err)
{
    return advance(s, GR_FLIGHT_LINEAR, 3, 0, stop, smp, err, 0);
}

static int advance_2d_law(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err)
{
    return advance(s, GR_FLIGHT_LINEAR, 2, 1, stop, smp, err, 0);
}

static int advance_3d_law(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err)
{
    return advance(s, GR_FLIGHT_LINEAR, 3, 1, stop, smp, err, 0);
}

int gr_edmd_advance(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err)
{
    /* a driven gas runs the plain loop between kicks (drive.c): nothing per event here */
    if (s->cfg.drive_kind != GR_DRIVE_NONE) return gr_drive_advance(s, stop, smp, err);
    return gr_edmd_advance_plain(s, stop, smp, err);
}

int gr_edmd_advance_plain(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err)
{
    if (s->nl.broken) {
        gr_error_set(err, GR_ERR_NOMEM, -1, -1, s->t, (double)s->nl.cap,
                     "a neighbour list could not grow earlier; the system cannot go on");
        return GR_ERR_NOMEM;
    }
    if (dynamics_of(s) == GR_FLIGHT_GRAVITY) return gr_edmd_advance_gravity(s, stop, smp, err);
    if (s->spin || s->cfg.vib.on) return gr_edmd_advance_extra(s, stop, smp, err);
    if (s->cfg.law.kind != GR_LAW_CONSTANT || s->cfg.wall_law.kind != GR_LAW_CONSTANT)
        return s->dim == 2 ? advance_2d_law(s, stop, smp, err) : advance_3d_law(s, stop, smp, err);
    return s->dim == 2 ? advance_2d(s, stop, smp, err) : advance_3d(s, stop, smp, err);
}
#elif defined(GR_EDMD_GRAVITY_UNIT)
/* a vibrating floor under gravity (vibwall.h: its search bounds the gap's curvature by
 * |g| + A omega^2): advance_vib's loops in this unit */
static int advance_2d_vib(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err)
{
    return advance(s, GR_FLIGHT_GRAVITY, 2, GR_VIB_LAWS, stop, smp, err, 1);
}

static int advance_3d_vib(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err)
{
    return advance(s, GR_FLIGHT_GRAVITY, 3, GR_VIB_LAWS, stop, smp, err, 1);
}

#ifndef GR_EDMD_GRAVITY_ROUGH_UNIT
/* Gravity (flight.h, GR_FLIGHT_GRAVITY): one loop per dimension, compiled with the laws'
 * code (a constant restitution is then one test of the law's kind per collision). */
static int advance_2d_gravity(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                              gr_error *err)
{
    return advance(s, GR_FLIGHT_GRAVITY, 2, 1, stop, smp, err, 0);
}

static int advance_3d_gravity(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                              gr_error *err)
{
    return advance(s, GR_FLIGHT_GRAVITY, 3, 1, stop, smp, err, 0);
}

int gr_edmd_advance_gravity(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                            gr_error *err)
{
    if (s->spin) return gr_edmd_advance_gravity_rough(s, stop, smp, err);
    if (s->cfg.vib.on) return advance_vib(s, stop, smp, err);
    return s->dim == 2 ? advance_2d_gravity(s, stop, smp, err)
                       : advance_3d_gravity(s, stop, smp, err);
}
#else
/* Rough particles under gravity (rule.h; spins do not change in flight: no torque), with
 * or without a vibrating floor (smooth for them, as every wall). */
static int advance_2d_gravity_rough(gr_edmd *s, const gr_edmd_stop *stop,
                                    gr_edmd_samples *smp, gr_error *err)
{
    return advance(s, GR_FLIGHT_GRAVITY, 2, GR_RULE_ROUGH, stop, smp, err, 0);
}

static int advance_3d_gravity_rough(gr_edmd *s, const gr_edmd_stop *stop,
                                    gr_edmd_samples *smp, gr_error *err)
{
    return advance(s, GR_FLIGHT_GRAVITY, 3, GR_RULE_ROUGH, stop, smp, err, 0);
}

int gr_edmd_advance_gravity_rough(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                                  gr_error *err)
{
    if (s->cfg.vib.on) return advance_vib(s, stop, smp, err);
    return s->dim == 2 ? advance_2d_gravity_rough(s, stop, smp, err)
                       : advance_3d_gravity_rough(s, stop, smp, err);
}
#endif
#else
/* A vibrating wall's loops (vibwall.h): compiled with the law rule (which takes a
 * constant restitution from the config as well), so two loops, not four; in
 * edmd_rough_vib.c with the rough rule (beside the wall, which is smooth for them). */
static int advance_2d_vib(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err)
{
    return advance(s, GR_FLIGHT_LINEAR, 2, GR_VIB_LAWS, stop, smp, err, 1);
}

static int advance_3d_vib(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err)
{
    return advance(s, GR_FLIGHT_LINEAR, 3, GR_VIB_LAWS, stop, smp, err, 1);
}

#ifndef GR_EDMD_VIB_ROUGH_UNIT
/* Rough particles (rule.h): the law rule's code with the tangential impulse and spins. */
static int advance_2d_rough(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                            gr_error *err)
{
    return advance(s, GR_FLIGHT_LINEAR, 2, GR_RULE_ROUGH, stop, smp, err, 0);
}

static int advance_3d_rough(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                            gr_error *err)
{
    return advance(s, GR_FLIGHT_LINEAR, 3, GR_RULE_ROUGH, stop, smp, err, 0);
}

int gr_edmd_advance_extra(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                          gr_error *err)
{
    if (s->spin && s->cfg.vib.on) return gr_edmd_advance_vib_rough(s, stop, smp, err);
    if (s->spin) /* a scene with spins: the rough rule, with or without laws */
        return s->dim == 2 ? advance_2d_rough(s, stop, smp, err)
                           : advance_3d_rough(s, stop, smp, err);
    return advance_vib(s, stop, smp, err);
}
#else
int gr_edmd_advance_vib_rough(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp,
                              gr_error *err)
{
    return advance_vib(s, stop, smp, err);
}
#endif
#endif

#if defined(GR_EDMD_GRAVITY_UNIT) || defined(GR_EDMD_EXTRA_UNIT)
/* A vibrating wall's run: this unit's loops for it (advance_2d_vib, advance_3d_vib) unless float64
 * cannot time the wall's phase at the end of the run (or, without a time limit, now):
 * there omega t's rounding, omega ulp(t), passes GR_VIB_PHASE_RESOLUTION and the wall's
 * position is known to less than A 2^-26. */
static int advance_vib(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err)
{
    const double t_end = stop->t_stop < INFINITY ? stop->t_stop : s->t;
    if (!(vw_phase_resolution(&s->cfg.vib, t_end) <= GR_VIB_PHASE_RESOLUTION)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, t_end, s->cfg.vib.omega,
                     "float64 cannot time the vibrating wall at this time: its phase omega t "
                     "would be resolved to worse than 2^-26 radians (omega ulp(t)); a run may "
                     "last up to about t = 2^26 / omega");
        return GR_ERR_VALUE;
    }
    return s->dim == 2 ? advance_2d_vib(s, stop, smp, err) : advance_3d_vib(s, stop, smp, err);
}
#endif

/* Move the system clock forward to t, integrating the kinetic energy on the way
 * (flight.h: with constant velocity it changes only at collisions, so the integral is
 * exact up to rounding; under gravity it changes in flight, and so does the momentum). */
static inline void set_clock(gr_edmd *s, int dyn, double t)
{
    if (t > s->t) {
        s->kinetic_time += fl_kinetic_integral(dyn, s->dim, &s->kinetic,
                                               s->momentum, s->mass_total, s->cfg.gravity,
                                               t - s->t);
        s->t = t;
    }
}

/* The time of the next sample due, +inf if none. */
static inline double next_sample(const gr_edmd_samples *smp)
{
    return smp && smp->next < smp->count ? smp->times[smp->next] : INFINITY;
}

/* ---- the events ---- */

static inline double kinetic_of(const gr_edmd *s, int dyn, int dim, int32_t i)
{
    return fl_kinetic(dyn, dim, s->mass[i], VEL(rec(s, dim, i), dim));
}

/* Collapse bookkeeping for a collision of i at t: count collisions that follow the
 * previous one of the same particle within eps_t. */
static inline int streak(gr_edmd *s, int32_t i, double t)
{
    gr_sched *e = &s->sched[i];
    if (t - e->t_last <= s->eps_t) e->streak += e->streak < INT8_MAX;
    else e->streak = 0;
    e->t_last = t;
    return e->streak > GR_COLLAPSE_STREAK;
}

/* The collision rule on the pair (i, j) at separation dr, velocities vp, vq (vq an image's
 * in a sheared box): the rough rule (rule.h) in the units that compile it, with the spins
 * as they are (the images slide, they do not turn) and its loss booked (translation and
 * rotation: the kinetic energy alone cannot tell it; stats' collision_loss), else the smooth
 * one.  tc_elastic: the TC model made this collision elastic, and so smooth (it keeps the
 * energy).  Returns the virial (rule_pair_apply). */
static GR_ALWAYS_INLINE double pair_rule(gr_edmd *s, int dim, int laws, int32_t i, int32_t j,
                                         const double *dr, double *vp, double *vq,
                                         double ri, double rj, double xi, int tc_elastic)
{
    if (GR_UNIT_ROUGH && GR_RULE_IS_ROUGH(laws)) {
        const int w = dim == 2 ? 1 : 3; /* spin components */
        const double beta = tc_elastic ? -1.0 : s->cfg.tangential_restitution;
        double loss;
        const double vir = rule_rough_apply(dim, dr, vp, vq, s->spin + (size_t)i * w,
                                            s->spin + (size_t)j * w, s->mass[i], s->mass[j],
                                            ri, rj, s->cfg.inertia_factor, xi, beta,
                                            s->cfg.friction, &loss);
        s->collision_loss += loss;
        return vir;
    }
    return rule_pair_apply(dim, dr, vp, vq, s->mass[i], s->mass[j], xi);
}

static GR_ALWAYS_INLINE int do_pair(gr_edmd *s, int dyn, int dim, int laws, int32_t i, int32_t j,
                                    double t, gr_error *err)
{
    if (s->le) return do_pair_sheared(s, dyn, dim, laws, i, j, t, err);
    double *p = rec(s, dim, i), *q = rec(s, dim, j);
    move(s, dyn, dim, p, t);
    move(s, dyn, dim, q, t);
    double dr[3];
    for (int a = 0; a < dim; a++) {
        dr[a] = q[a] - p[a];
        /* contact distance < L/2, so the nearest image is the one */
        if (s->cfg.periodic) dr[a] = bd_nearest(dr[a], s->L[a]);
    }
    int64_t clamped; /* 1 if xi is the law's at its range's end */
    const int64_t elastic_before = s->elastic_tc;
    const double xi = rule_pair_eps(&s->cfg, laws, dim, dr, VEL(p, dim), VEL(q, dim), t,
                                    &s->sched[i], &s->sched[j], &clamped, &s->elastic_tc);
    double before = kinetic_of(s, dyn, dim, i) + kinetic_of(s, dyn, dim, j);
    double vb[6]; /* the velocities before, for the stress tensor */
    if (s->cfg.stress)
        for (int a = 0; a < dim; a++) vb[a] = VEL(p, dim)[a], vb[3 + a] = VEL(q, dim)[a];
    const double vir = pair_rule(s, dim, laws, i, j, dr, VEL(p, dim), VEL(q, dim), RAD(p, dim),
                                 RAD(q, dim), xi, s->elastic_tc != elastic_before);
    if (vir < 0.0) { /* grazing: no longer approaching at contact after rounding */
        s->invalid++;
        predict(s, dyn, dim, i);
        predict(s, dyn, dim, j);
        return GR_OK;
    }
    s->kinetic += kinetic_of(s, dyn, dim, i) + kinetic_of(s, dyn, dim, j) - before;
    s->virial += vir;
    if (s->cfg.stress)
        stress_pair(s, dim, t, dr, s->mass[i], vb, VEL(p, dim), s->mass[j], vb + 3, VEL(q, dim));
    s->pair++;
    s->law_clamped += clamped; /* a collision that happened, with the clamped law's eps */
    s->sched[i].count++;
    s->sched[j].count++;
    int collapse_i = streak(s, i, t), collapse_j = streak(s, j, t);
    s->sched[i].last = j;
    s->sched[j].last = i;
    if (collapse_i || collapse_j) {
        gr_error_set(err, GR_ERR_COLLAPSE, uid(s, i), uid(s, j), t, (double)GR_COLLAPSE_STREAK,
                     GR_XSTR(GR_COLLAPSE_STREAK) " successive collisions of one particle, "
                     "each within 1e-9 of a free-flight time of the previous");
        predict(s, dyn, dim, i);
        predict(s, dyn, dim, j);
        return GR_ERR_COLLAPSE;
    }
    predict(s, dyn, dim, i);
    predict(s, dyn, dim, j);
    return GR_OK;
}

static GR_ALWAYS_INLINE int do_wall(gr_edmd *s, int dyn, int dim, int laws, int32_t i, int wall,
                                    double t, gr_error *err)
{
    double *p = rec(s, dim, i), *v = VEL(p, dim);
    const int a = wall >> 1, up = wall & 1;
    move(s, dyn, dim, p, t);
    if (wall == 2 * dim) { /* a sheared box's slide (lees_edwards.h): rescan */
        predict(s, dyn, dim, i);
        return GR_OK;
    }
    double before = kinetic_of(s, dyn, dim, i), vn = v[a], v_before[3];
    if (dyn == GR_FLIGHT_GRAVITY) /* the wall's impulse changes the total momentum */
        for (int k = 0; k < dim; k++) v_before[k] = v[k];
    int64_t clamped; /* 1 if e_w is the law's at its range's end */
    const double ew = rule_wall_eps(&s->cfg, laws, vn, t, &s->sched[i], &clamped);
    s->law_clamped += clamped;
    double vb[3]; /* the velocity before, for the stress tensor */
    if (s->cfg.stress)
        for (int k = 0; k < dim; k++) vb[k] = v[k];
    rule_wall_apply(dim, v, a, ew);
    if (s->cfg.stress) stress_wall(s, dim, t, s->mass[i], vb, v);
    p[a] = up ? bd_wall_stop_hi(s->cfg.hi[a], RAD(p, dim))
              : bd_wall_stop_lo(s->cfg.lo[a], RAD(p, dim));
    for (int k = 0; k < dim; k++) {
        if (!isfinite(v[k])) {
            gr_error_set(err, GR_ERR_NONFINITE, uid(s, i), -1, t, v[k], "a velocity after a heated wall");
            return GR_ERR_NONFINITE;
        }
    }
    s->wall_impulse += s->mass[i] * (fabs(vn) + fabs(v[a]));
    s->kinetic += kinetic_of(s, dyn, dim, i) - before;
    if (dyn == GR_FLIGHT_GRAVITY)
        for (int k = 0; k < dim; k++) s->momentum[k] += s->mass[i] * (v[k] - v_before[k]);
    s->wall++;
    s->sched[i].count++;
    s->sched[i].last = -2 - wall;
    if (streak(s, i, t)) {
        gr_error_set(err, GR_ERR_COLLAPSE, uid(s, i), -1, t, (double)GR_COLLAPSE_STREAK,
                     GR_XSTR(GR_COLLAPSE_STREAK) " successive collisions of one particle, "
                     "each within 1e-9 of a free-flight time of the previous");
        predict(s, dyn, dim, i);
        return GR_ERR_COLLAPSE;
    }
    predict(s, dyn, dim, i);
    return GR_OK;
}

/* A hit on the vibrating wall (vibwall.h) at t: the particle is reflected in the wall's
 * frame -- its velocity relative to the wall, U along the axis, mirrored and scaled by e_w
 * as at a fixed wall (thesis 2.22) -- and placed on the wall.  The wall's work J U (J the
 * normal impulse it gives) and the energy lost, m (1 - e_w^2) |v - U|^2 / 2, are counted
 * (wall_work, collision_loss: the kinetic energy changes by exactly their difference).  A
 * particle found not approaching the wall (a graze at the scale of rounding) is left as it
 * is and predicted again from t: the search then starts beyond the touch; so is one that
 * only enters the wall's band (vibwall.h: the search for the contact starts there).  Both
 * count as stale events. */
static GR_ALWAYS_INLINE int do_vibwall(gr_edmd *s, int dyn, int dim, int laws, int32_t i,
                                       double t, gr_error *err)
{
    const gr_vibwall *w = &s->cfg.vib;
    double *p = rec(s, dim, i), *v = VEL(p, dim);
    const int a = w->axis;
    move(s, dyn, dim, p, t);
    const double U = vw_velocity(w, t), vn = v[a], rel = vn - U;
    /* entering the wall's band (the search starts now), or a graze at rounding's scale */
    if (!vw_touching(w, s->cfg.lo[a], s->cfg.hi[a], t, p[a], vn, RAD(p, dim)) ||
        !((w->side ? -rel : rel) < 0.0)) {
        s->invalid++;
        predict(s, dyn, dim, i);
        return GR_OK;
    }
    const double m = s->mass[i], before = kinetic_of(s, dyn, dim, i);
    double w2 = 0.0; /* |v - U|^2 */
    for (int k = 0; k < dim; k++) w2 += k == a ? rel * rel : v[k] * v[k];
    double vb[3]; /* the velocity before, for the stress tensor and the momentum */
    for (int k = 0; k < dim; k++) vb[k] = v[k];
    int64_t clamped;
    const double ew = rule_wall_eps(&s->cfg, laws, rel, t, &s->sched[i], &clamped);
    s->law_clamped += clamped;
    v[a] = rel;
    rule_wall_apply(dim, v, a, ew);
    v[a] += U;
    p[a] = vw_position(w, s->cfg.lo[a], s->cfg.hi[a], t) + (w->side ? -RAD(p, dim) : RAD(p, dim));
    for (int k = 0; k < dim; k++) {
        if (!isfinite(v[k])) {
            gr_error_set(err, GR_ERR_NONFINITE, uid(s, i), -1, t, v[k],
                         "a velocity after the vibrating wall");
            return GR_ERR_NONFINITE;
        }
    }
    if (s->cfg.stress) stress_wall(s, dim, t, m, vb, v);
    if (dyn == GR_FLIGHT_GRAVITY) /* the wall's impulse changes the total momentum */
        for (int k = 0; k < dim; k++) s->momentum[k] += m * (v[k] - (k == a ? vn : vb[k]));
    const double J = m * (v[a] - vn);
    s->wall_impulse += fabs(J);
    s->wall_work += J * U;
    s->collision_loss += 0.5 * m * (1.0 - ew * ew) * w2;
    s->kinetic += kinetic_of(s, dyn, dim, i) - before;
    s->wall++;
    s->sched[i].count++;
    s->sched[i].last = -2 - (2 * a + w->side);
    if (streak(s, i, t)) {
        gr_error_set(err, GR_ERR_COLLAPSE, uid(s, i), -1, t, (double)GR_COLLAPSE_STREAK,
                     GR_XSTR(GR_COLLAPSE_STREAK) " successive collisions of one particle, "
                     "each within 1e-9 of a free-flight time of the previous");
        predict(s, dyn, dim, i);
        return GR_ERR_COLLAPSE;
    }
    predict(s, dyn, dim, i);
    return GR_OK;
}

static void predict_cross(gr_edmd *s, int dyn, int dim, int32_t i);
static void schedule(gr_edmd *s, int32_t i);

/* ---- the events of a sheared (Lees-Edwards) box, boundary.h ---- */

/* do_pair in a sheared box: a partner seen through an image across a y face is displaced
 * along x by -+delta and moves with v_x -+ u.  The rule acts on that image's velocity;
 * the kinetic energy in the box's velocities then changes by the work of the images, the
 * x impulse carried across the face times u (shear_work).  A function of its own: the
 * plain loop pays one test per pair collision for it. */
static int do_pair_sheared(gr_edmd *s, int dyn, int dim, int laws, int32_t i, int32_t j,
                           double t, gr_error *err)
{
    double *p = rec(s, dim, i), *q = rec(s, dim, j);
    move(s, dyn, dim, p, t);
    move(s, dyn, dim, q, t);
    double dr[3], vq[3];
    for (int a = 0; a < dim; a++) dr[a] = bd_nearest(q[a] - p[a], s->L[a]);
    /* the offset (an fmod) only for a pair across a y face, the one that uses it */
    const double delta = fabs(q[1] - p[1]) > 0.5 * s->L[1]
                             ? bd_le_offset(s->cfg.shear_offset, s->le_u, t, s->L[0])
                             : 0.0;
    const int ky = bd_le_image(dr, q[1] - p[1], s->L[1], s->L[0], delta);
    const double vx = (double)ky * s->le_u;
    for (int a = 0; a < dim; a++) vq[a] = VEL(q, dim)[a];
    vq[0] += vx;
    int64_t clamped;
    const int64_t elastic_before = s->elastic_tc;
    const double xi = rule_pair_eps(&s->cfg, laws, dim, dr, VEL(p, dim), vq, t, &s->sched[i],
                                    &s->sched[j], &clamped, &s->elastic_tc);
    const double before = kinetic_of(s, dyn, dim, i) + kinetic_of(s, dyn, dim, j);
    const double vq0 = vq[0];
    double Vb[6]; /* the peculiar velocities before, for the stress tensor (stress.h) */
    if (s->cfg.stress) {
        stress_le_peculiar(s, dim, p, t, Vb);
        stress_le_peculiar(s, dim, q, t, Vb + 3);
    }
    /* on the image's velocity vq (the loss is the same in every frame) */
    const double vir = pair_rule(s, dim, laws, i, j, dr, VEL(p, dim), vq, RAD(p, dim),
                                 RAD(q, dim), xi, s->elastic_tc != elastic_before);
    if (vir < 0.0) { /* grazing (do_pair) */
        s->invalid++;
        predict(s, dyn, dim, i);
        predict(s, dyn, dim, j);
        return GR_OK;
    }
    for (int a = 0; a < dim; a++) VEL(q, dim)[a] = vq[a];
    VEL(q, dim)[0] = vq[0] - vx;
    if (s->cfg.stress) { /* dr: through the image; j's impulse as its image received it */
        double Va[6];
        stress_le_peculiar(s, dim, p, t, Va);
        stress_le_peculiar(s, dim, q, t, Va + 3);
        stress_pair(s, dim, t, dr, s->mass[i], Vb, Va, s->mass[j], Vb + 3, Va + 3);
    }
    /* the image's x momentum change, -m_j (vq' - vq), crossed the face: work -ky u of it */
    s->shear_work -= vx * s->mass[j] * (vq[0] - vq0);
    s->kinetic += kinetic_of(s, dyn, dim, i) + kinetic_of(s, dyn, dim, j) - before;
    s->virial += vir;
    s->pair++;
    s->law_clamped += clamped;
    s->sched[i].count++;
    s->sched[j].count++;
    int collapse_i = streak(s, i, t), collapse_j = streak(s, j, t);
    s->sched[i].last = j;
    s->sched[j].last = i;
    predict(s, dyn, dim, i);
    predict(s, dyn, dim, j);
    if (collapse_i || collapse_j) {
        gr_error_set(err, GR_ERR_COLLAPSE, uid(s, i), uid(s, j), t, (double)GR_COLLAPSE_STREAK,
                     GR_XSTR(GR_COLLAPSE_STREAK) " successive collisions of one particle, "
                     "each within 1e-9 of a free-flight time of the previous");
        return GR_ERR_COLLAPSE;
    }
    return GR_OK;
}

/* do_cross in a sheared box, for a particle i (clock at t, cell `old`) that has just left
 * through the upper (up = 1) or lower y face and re-entered at the other (its y and img_y
 * moved by bd_through_face): its x moves by -+delta and its v_x by -+u, its x image
 * counter takes the whole box lengths of D(t) that delta dropped (boundary.h: unwrapped x
 * is continuous), its cell is found anew and, its velocity changed, everything about it
 * is predicted afresh.  The predictions of others with i stay right: i's image through
 * the face moves on the straight line i had. */
static void do_face_sheared(gr_edmd *s, int dyn, int dim, int32_t i, double t, int up,
                            int32_t old)
{
    double *p = rec(s, dim, i);
    le_face_moves(s, dyn, dim, i, t, up);
    gr_sched *e = &s->sched[i];
    e->c[1] = up ? 0 : s->cells.nc[1] - 1;
    cell_coords(&s->cells, 1, p, e->c); /* x only */
    cell_remove(&s->cells, i, old);
    cell_insert(&s->cells, i, cell_of(&s->cells, dim, e->c));
    s->crossings++;
    predict(s, dyn, dim, i);
}

/* What a re-entry through a sheared face does to particle i (clock at t, its y and img_y
 * already moved by bd_through_face, x in the box): x by -+delta and v_x by -+u, img_x
 * the whole box lengths of D(t) that delta dropped, the work and the energy (do_face_sheared,
 * and a sheared box's shell exit). */
static void le_face_moves(gr_edmd *s, int dyn, int dim, int32_t i, double t, int up)
{
    double *p = rec(s, dim, i), *v = VEL(p, dim);
    int64_t *img = &s->image[(size_t)i * dim];
    const double D = bd_le_total(s->cfg.shear_offset, s->le_u, t);
    const double delta = bd_le_offset(s->cfg.shear_offset, s->le_u, t, s->L[0]);
    const double sign = up ? -1.0 : 1.0, before = kinetic_of(s, dyn, dim, i), v0 = v[0];
    p[0] += sign * delta;
    v[0] += sign * s->le_u;
    /* x + img_x L_x + img_y D stays (img_y moved by -sign): sign (D - delta) is a whole
     * number of box lengths */
    img[0] += (int64_t)llround(sign * (D - delta) / s->L[0]);
    bd_reenter(&p[0], s->cfg.lo[0], s->cfg.hi[0], s->L[0], &img[0]);
    s->shear_work += sign * s->le_u * s->mass[i] * 0.5 * (v0 + v[0]);
    s->kinetic += kinetic_of(s, dyn, dim, i) - before;
}

/* A sheared box's shell exit brings i (clock at t) back into the box: x first, then
 * through a y face with le_face_moves (which leaves x in the box again), then z.
 * Returns 1 if it moved. */
static int le_list_reenter(gr_edmd *s, int dyn, int dim, int32_t i, double t)
{
    double *p = rec(s, dim, i);
    int64_t *img = &s->image[(size_t)i * dim];
    int moved = bd_reenter(&p[0], s->cfg.lo[0], s->cfg.hi[0], s->L[0], &img[0]);
    const int up = p[1] >= s->cfg.hi[1];
    if (bd_reenter(&p[1], s->cfg.lo[1], s->cfg.hi[1], s->L[1], &img[1])) {
        le_face_moves(s, dyn, dim, i, t, up);
        moved = 1;
    }
    if (dim == 3 && bd_reenter(&p[2], s->cfg.lo[2], s->cfg.hi[2], s->L[2], &img[2])) moved = 1;
    return moved;
}

/* Cell mode: i moves into the next cell, wrapping around a periodic box. */
static GR_ALWAYS_INLINE void do_cross(gr_edmd *s, int dyn, int dim, int32_t i, double t)
{
    double *p = rec(s, dim, i);
    gr_sched *e = &s->sched[i];
    int32_t *c = e->c;
    const int a = e->cross >> 1, dir = (e->cross & 1) ? 1 : -1;
    move(s, dyn, dim, p, t);
    int32_t old = cell_of(&s->cells, dim, c);
    int32_t q = c[a] + dir;
    if (q >= s->cells.nc[a]) { /* out of the last cell: out of a periodic box (boundary.h) */
        q = 0;
        bd_through_face(&p[a], s->L[a], &s->image[(size_t)i * dim + a], 1);
        if (a == 1 && s->le) {
            do_face_sheared(s, dyn, dim, i, t, 1, old);
            return;
        }
    } else if (q < 0) {
        q = s->cells.nc[a] - 1;
        bd_through_face(&p[a], s->L[a], &s->image[(size_t)i * dim + a], 0);
        if (a == 1 && s->le) {
            do_face_sheared(s, dyn, dim, i, t, 0, old);
            return;
        }
    }
    c[a] = q;
    if (!s->big.is_big[i]) {
        cell_remove(&s->cells, i, old);
        cell_insert(&s->cells, i, cell_of(&s->cells, dim, c));
    }
    s->crossings++;
    predict_cross(s, dyn, dim, i);
    /* the key is most often the crossing: its calendar bucket is asked for before the
     * scan, which then overlaps that miss */
    if (s->lookahead) gr_cq_prefetch_key(&s->queue, e->t_cross < e->t_coll ? e->t_cross : e->t_coll);
    scan_cells(s, dyn, dim, i, a, dir);
    schedule(s, i);
}


/* List mode: i (clock at t) has left its shell.  Its list is rebuilt about its present
 * position, which is first brought back into a periodic box (between rebuilds a
 * particle may stray up to delta beyond the box: pair tests take the nearest image).
 * Brought back, i is seen from its neighbours through other images: it is taken off
 * every neighbour's row and linked anew; otherwise only the neighbours that leave or
 * join its list change (relink, search.h). */
static GR_ALWAYS_INLINE int do_shell_exit(gr_edmd *s, int dyn, int dim, int32_t i, double t,
                                          gr_error *err)
{
    double *p = rec(s, dim, i);
    gr_sched *e = &s->sched[i];
    move(s, dyn, dim, p, t);
    int wrapped = 0;
    if (s->le) {
        wrapped = le_list_reenter(s, dyn, dim, i, t); /* through a sliding face too */
        if (t > s->nl.tref + s->nl.span) le_refile(s, dim, t); /* (le_cells.h) */
    } else if (s->cfg.periodic) {
        for (int a = 0; a < dim; a++) /* not wrapped |= ...: that costs the cell-crossing
                                        * loop 5 instructions an event (cachegrind) */
            if (bd_reenter(&p[a], s->cfg.lo[a], s->cfg.hi[a], s->L[a],
                           &s->image[(size_t)i * dim + a]))
                wrapped = 1;
    }
    /* the neighbours' list lengths and rows are misses: ask for all of them first (with
     * relinking, for the few that leave; the search for new ones gives them time) */
    const int32_t *row = nl_row(&s->nl, i);
    for (int k = 0; k < e->nn; k++) {
        GR_PREFETCH(&s->sched[row[k] >> GR_NL_BITS]);
        GR_PREFETCH(nl_row(&s->nl, row[k] >> GR_NL_BITS));
    }
    if (wrapped) {
        for (int k = 0; k < e->nn; k++) nl_unlink(&s->nl, s->sched, row[k] >> GR_NL_BITS, i);
        e->nn = 0;
    }
    const int32_t old = cell_of(&s->cells, dim, e->c);
    set_centre(s, dim, i);
    const int32_t cell = cell_of(&s->cells, dim, e->c);
    if (cell != old) {
        cell_remove(&s->cells, i, old);
        cell_insert(&s->cells, i, cell);
        if (s->le) { /* the blocks the sheared search reads (le_cells.h) */
            le_sync_cell(&s->cells, s->nl.blocks, old);
            le_sync_cell(&s->cells, s->nl.blocks, cell);
        }
    }
    const int32_t m = find_near(s, dim, i, 0);
    int status = wrapped ? link_all(s, dim, i, m, err) : relink(s, dim, i, m, err);
    if (status != GR_OK) return status;
    s->shell_exits++;
    predict(s, dyn, dim, i);
    return GR_OK;
}

/* ---- predictions ---- */

/* The list scan's compilation in use: AVX2's four lanes where the CPU has them, unless
 * GRANULAR_SCAN_KERNEL=plain (the tests run both: the bits must not depend on it). */
#if defined(GR_EDMD_GRAVITY_UNIT)
static const int scan_avx2 = 0; /* gravity runs the plain scan (predict) */
#elif defined(GR_EDMD_EXTRA_UNIT)
#define scan_avx2 gr_scan_avx2 /* the plain unit's, set once */
#else
int gr_scan_avx2;
#define scan_avx2 gr_scan_avx2

void gr_scan_init(void)
{
#ifdef GR_SCAN_X86
    const char *want = getenv("GRANULAR_SCAN_KERNEL");
    __builtin_cpu_init();
    scan_avx2 = __builtin_cpu_supports("avx2") && !(want && strcmp(want, "plain") == 0);
#endif
}

const char *gr_scan_kernel(void)
{
    return scan_avx2 ? "avx2" : "plain";
}
#endif

static void predict_wall(gr_edmd *s, int dyn, int dim, int32_t i);

/* Full prediction for i, whose clock must be the current time: walls, then pair
 * collisions and the next crossing (cells) or shell exit (lists). */
static void predict(gr_edmd *s, int dyn, int dim, int32_t i)
{
    predict_wall(s, dyn, dim, i);
    if (s->nl.shell > 0.0 && s->le) { /* the sliding images (le_nlist.h) */
        le_shell_exit(s, dyn, dim, i);
        /* only a centre in a row next to a y face can list through it: the others scan
         * as in a plain box */
        const int face = le_edge_row(&s->cells, s->sched[i].c[1]);
#ifdef GR_SCAN_X86
        if (dim == 3 && dyn == GR_FLIGHT_LINEAR && scan_avx2) {
            if (face) scan_list_avx2_sheared(s, i);
            else scan_list_avx2(s, i);
        } else
#endif
        if (face) le_scan_list(s, dyn, dim, i);
        else scan_list(s, dyn, dim, i);
    } else if (s->nl.shell > 0.0) {
        const double *p = rec(s, dim, i);
        s->sched[i].t_cross = TIME(p, dim) + fl_exit_time(dyn, dim, p, VEL(p, dim),
                                                       s->cfg.gravity, s->nl.centre + (size_t)i * (dim + 1),
                                                       s->nl.exit2);
#ifdef GR_SCAN_X86
        /* the four-lane scan is written for straight lines (GR_FL_SEP) */
        if (dim == 3 && dyn == GR_FLIGHT_LINEAR && scan_avx2) scan_list_avx2(s, i);
        else
#endif
            scan_list(s, dyn, dim, i);
    } else {
        predict_cross(s, dyn, dim, i); /* first: its bucket is asked for while the scan runs */
        if (s->lookahead) gr_cq_prefetch_key(&s->queue, s->sched[i].t_cross);
        scan_cells(s, dyn, dim, i, -1, 0);
    }
    schedule(s, i);
}

/* The queue key of i: the earlier of its collision and its crossing or shell exit. */
static inline void schedule(gr_edmd *s, int32_t i)
{
    const gr_sched *e = &s->sched[i];
    gr_cq_update(&s->queue, i, e->t_coll < e->t_cross ? e->t_coll : e->t_cross);
}

/* predict_wall with a vibrating wall: its hit time (vibwall.h), and the fixed walls, its
 * own face not among them.  A scene without one never comes here (one test of a flag the
 * walled box's prediction reads anyway). */
static void predict_wall_vib(gr_edmd *s, int dyn, int dim, int32_t i)
{
    const double *p = rec(s, dim, i), *v = VEL(p, dim);
    const gr_vibwall *w = &s->cfg.vib;
    gr_sched *e = &s->sched[i];
    double best = vw_hit_time(w, dyn, s->cfg.gravity[w->axis], s->cfg.lo[w->axis], s->cfg.hi[w->axis],
                              TIME(p, dim), p[w->axis], v[w->axis], RAD(p, dim));
    int32_t wall = best < INFINITY ? 2 * w->axis + w->side : -1;
    for (int a = 0; a < dim; a++) {
        double dt;
        double lo_stop = bd_wall_stop_lo(s->cfg.lo[a], RAD(p, dim));
        double hi_stop = bd_wall_stop_hi(s->cfg.hi[a], RAD(p, dim));
        if (a == w->axis) { /* the vibrating face is out of reach of this test */
            if (w->side) hi_stop = INFINITY;
            else lo_stop = -INFINITY;
        }
        const int up = fl_wall_time(dyn, p[a], v[a], s->cfg.gravity[a], lo_stop, hi_stop, &dt);
        if (up < 0 || !(dt < INFINITY)) continue;
        if (dt < 0.0) dt = 0.0;
        if (dt < best) {
            best = dt;
            wall = 2 * a + up;
        }
    }
    if (wall >= 0) {
        e->t_coll = TIME(p, dim) + best;
        e->partner = -2 - wall;
    }
}

/* i's next wall collision (none in a periodic box), replacing its prediction. */
static inline void predict_wall(gr_edmd *s, int dyn, int dim, int32_t i)
{
    const double *p = rec(s, dim, i), *v = VEL(p, dim);
    gr_sched *e = &s->sched[i];
    e->t_coll = INFINITY;
    e->partner = -1;
    if (s->cfg.periodic) return;
    if (s->cfg.vib.on) {
        predict_wall_vib(s, dyn, dim, i);
        return;
    }
    double best = INFINITY;
    int32_t wall = -1;
    for (int a = 0; a < dim; a++) {
        double dt;
        const int up = fl_wall_time(dyn, p[a], v[a], s->cfg.gravity[a], bd_wall_stop_lo(s->cfg.lo[a], RAD(p, dim)),
                                    bd_wall_stop_hi(s->cfg.hi[a], RAD(p, dim)), &dt);
        if (up < 0) continue;
        if (dt < 0.0) dt = 0.0;
        if (dt < best) {
            best = dt;
            wall = 2 * a + up;
        }
    }
    if (wall >= 0) {
        e->t_coll = TIME(p, dim) + best;
        e->partner = -2 - wall;
    }
}

/* Cell mode: next cell crossing of i from its current position, cell and velocity. */
static GR_ALWAYS_INLINE void predict_cross_in(gr_edmd *s, int dyn, int dim, int32_t i, const int periodic)
{
    /* Without branches on the signs of the velocity: they differ from one event to the
     * next at random, and a mispredicted branch costs more than the arithmetic. */
    const gr_cells *g = &s->cells;
    const double *p = rec(s, dim, i);
    const int32_t *c = s->sched[i].c;
    double best = INFINITY;
    int32_t code = -1;
    for (int a = 0; a < dim; a++) {
        int up, open;
        double dt = fl_cross_time(dyn, p[a], VEL(p, dim)[a], s->cfg.gravity[a], s->cfg.lo[a],
                                  c[a], g->w[a], &up, &open);
        if (!periodic) /* a wall has no cell behind it */
            open &= bd_cell_beyond(up, c[a], g->nc[a]);
        dt = open ? dt : INFINITY;
        const int32_t earlier = dt < best;
        code += earlier * (2 * a + up - code); /* arithmetic: a select compiles to a branch */
        best = earlier ? dt : best;
    }
    s->sched[i].t_cross = TIME(p, dim) + best;
    s->sched[i].cross = (int8_t)code;
}

/* Compiled apart for periodic boxes, which have no walls to test for: fewer instructions
 * an event (counted in docs/performance.md). */
static inline void predict_cross(gr_edmd *s, int dyn, int dim, int32_t i)
{
    if (s->cfg.periodic) predict_cross_in(s, dyn, dim, i, 1);
    else predict_cross_in(s, dyn, dim, i, 0);
}

/* ---- the start ---- */

/* (the extra and rough loops start from the plain or gravity unit's predictions) */
#if !defined(GR_EDMD_EXTRA_UNIT) && !defined(GR_EDMD_GRAVITY_ROUGH_UNIT)
static int start(gr_edmd *s, int dyn, int dim, gr_error *err)
{
    if (s->nl.shell > 0.0) {
        for (int32_t i = 0; i < s->n; i++) set_centre(s, dim, i); /* the cells as filed */
        if (s->le) le_refile(s, dim, s->t); /* ... but for the flow's (le_cells.h) */
        for (int32_t i = 0; i < s->n; i++) {
            int status = link_all(s, dim, i, find_near(s, dim, i, 1), err);
            if (status != GR_OK) return status;
        }
    }
    int status = gr_renumber(s);
    if (status != GR_OK) return status;
    for (int32_t i = 0; i < s->n; i++) predict(s, dyn, dim, i);
    return GR_OK;
}
#endif

#if !defined(GR_EDMD_GRAVITY_UNIT) && !defined(GR_EDMD_EXTRA_UNIT)
int gr_predict_all(gr_edmd *s, gr_error *err)
{
    if (dynamics_of(s) == GR_FLIGHT_GRAVITY) return gr_predict_all_gravity(s, err);
    return s->dim == 2 ? start(s, GR_FLIGHT_LINEAR, 2, err) : start(s, GR_FLIGHT_LINEAR, 3, err);
}

/* A constant dynamics at every call of predict in this unit: a run-time one would make
 * the compiler's clones of the scans generic and cost the plain loop instructions. */
void gr_predict_one(gr_edmd *s, int32_t i)
{
    if (dynamics_of(s) == GR_FLIGHT_GRAVITY) gr_predict_one_gravity(s, i);
    else if (s->dim == 2) predict(s, GR_FLIGHT_LINEAR, 2, i); /* the clones the loops use */
    else predict(s, GR_FLIGHT_LINEAR, 3, i);
}
#elif defined(GR_EDMD_GRAVITY_UNIT) && !defined(GR_EDMD_GRAVITY_ROUGH_UNIT)
int gr_predict_all_gravity(gr_edmd *s, gr_error *err)
{
    return s->dim == 2 ? start(s, GR_FLIGHT_GRAVITY, 2, err) : start(s, GR_FLIGHT_GRAVITY, 3, err);
}

void gr_predict_one_gravity(gr_edmd *s, int32_t i)
{
    if (s->dim == 2) predict(s, GR_FLIGHT_GRAVITY, 2, i);
    else predict(s, GR_FLIGHT_GRAVITY, 3, i);
}
#endif
