/* rule.h -- the collision-rule seam: what a collision does to the particles, for a pair
 * and for a wall.  Each rule is two steps: the coefficient (rule_pair_eps, rule_wall_eps:
 * a constant xi, a law eps(v_n) from restitution.h, the TC model on top) and its
 * application (rule_pair_apply, rule_wall_apply: the impulse of collide.h, the wall's
 * reflection).  The events (edmd.c do_pair, do_wall) call these and keep only the
 * bookkeeping (energy, virial, counters, collapse).
 *
 * A rule is compiled in, not looked up: the loop's `laws` constant (edmd.c) chooses the
 * constant-xi rule (no law code at all) or the law rule, so a constant-xi run executes no
 * instruction of another rule.  A new rule (e.g. rough spheres: tangential restitution
 * beta, angular velocities) is one more pair of functions here and one more value of that
 * constant, with its own advance_* in edmd.c.
 *
 * A particle may carry more than position and velocity: a rough rule needs each
 * particle's angular velocity (and moment of inertia).  That state lives in an array of
 * its own in the system (gr_edmd, beside `mass`: n * 3 doubles in 3D, n in 2D, NULL for
 * scenes without it), NOT in the particle record (engine.h: x v t r, one 64-byte line in
 * 3D): every scan loads the records of all its candidates, and a wider record would
 * cost every scene in every scan, where the extra array is touched only by a collision of
 * the rule that uses it.  Under constant velocity (flight.h) an angular velocity does not
 * change in flight, so neither the clock nor the predictions read it; the checkpoint
 * would save the array when it exists. */
#ifndef GR_RULE_H
#define GR_RULE_H

#include <math.h>
#include <stdint.h>

#include "collide.h"
#include "common.h"
#include "edmd.h"
#include "restitution.h"
#include "schedstate.h"

/* The law's eps for a pair at contact: its normal approach speed |dv . dr| / |dr| (0 for
 * a pair that does not approach: gr_pair_collide refuses it).  *clamped += 1 if the speed
 * is past the law's range. */
static double rule_pair_law(const gr_law *law, int dim, const double *dr, const double *vi,
                            const double *vj, int64_t *clamped)
{
    double b = 0.0, dr2 = 0.0;
    for (int a = 0; a < dim; a++) {
        b += dr[a] * (vj[a] - vi[a]);
        dr2 += dr[a] * dr[a];
    }
    double vn = b < 0.0 && dr2 > 0.0 ? -b / sqrt(dr2) : 0.0;
    return gr_law_eval(law, vn, clamped);
}

/* The restitution of a pair (i, j) colliding at t with separation dr = x_j - x_i and
 * velocities vi, vj, with ei, ej their scheduling states (for the TC model's time since
 * each one's previous collision): the config's xi, or with `laws` its law's eps(v_n);
 * then, within the contact duration of a previous collision, 1 (the TC model: *elastic
 * += 1).  *clamped is set to 1 if the eps applied is the law's at its range's end (the
 * caller counts it only if the collision happens). */
static GR_ALWAYS_INLINE double rule_pair_eps(const gr_edmd_config *cfg, int laws, int dim,
                                             const double *dr, const double *vi,
                                             const double *vj, double t, const gr_sched *ei,
                                             const gr_sched *ej, int64_t *clamped,
                                             int64_t *elastic)
{
    double xi = cfg->restitution;
    *clamped = 0;
    if (laws && cfg->law.kind != GR_LAW_CONSTANT)
        xi = rule_pair_law(&cfg->law, dim, dr, vi, vj, clamped);
    if (cfg->contact_duration > 0.0 && xi < 1.0 &&
        (t - ei->t_last < cfg->contact_duration || t - ej->t_last < cfg->contact_duration)) {
        xi = 1.0; /* TC model: within t_c of a previous collision, collide elastically */
        ++*elastic;
        *clamped = 0; /* the clamped eps is not the one applied */
    }
    return xi;
}

/* The pair collision with restitution xi (collide.h): velocities vi, vj changed in
 * place; the virial dr . dp_j (>= 0), or -1 if the pair does not approach (then nothing
 * changed). */
static inline double rule_pair_apply(int dim, const double *dr, double *vi, double *vj,
                                     double mi, double mj, double xi)
{
    return gr_pair_collide(dim, dr, vi, vj, mi, mj, xi);
}

/* The restitution of a wall collision at t with normal velocity vn, ei the particle's
 * scheduling state: the config's e_w, or with `laws` its wall law's e_w(|vn|) (the same
 * rule, thesis 2.22); 1 within the contact duration of a previous collision.  *clamped
 * as for rule_pair_eps. */
static GR_ALWAYS_INLINE double rule_wall_eps(const gr_edmd_config *cfg, int laws, double vn,
                                             double t, const gr_sched *ei, int64_t *clamped)
{
    double ew = cfg->wall_restitution;
    *clamped = 0;
    if (laws && cfg->wall_law.kind != GR_LAW_CONSTANT)
        ew = gr_law_eval(&cfg->wall_law, fabs(vn), clamped);
    if (ew < 1.0 && cfg->contact_duration > 0.0 && t - ei->t_last < cfg->contact_duration) {
        ew = 1.0;
        *clamped = 0; /* TC model: the clamped e_w is not the one applied */
    }
    return ew;
}

/* The wall collision along axis a with restitution ew: v' = ew * (v reflected), the law
 * of reflection kept (thesis 2.22). */
static inline void rule_wall_apply(int dim, double *v, int a, double ew)
{
    v[a] = -v[a];
    if (ew != 1.0)
        for (int k = 0; k < dim; k++) v[k] *= ew;
}

#endif
