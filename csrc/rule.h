/* rule.h -- the collision-rule seam: what a collision does to the particles, for a pair
 * and for a wall.  Each rule is two steps: the coefficient (rule_pair_eps, rule_wall_eps:
 * a constant xi, a law eps(v_n) from restitution.h, the TC model on top) and its
 * application (rule_pair_apply, rule_wall_apply: the impulse of collide.h, the wall's
 * reflection).  The events (edmd.c do_pair, do_wall) call these and keep only the
 * bookkeeping (energy, virial, counters, collapse).
 *
 * A rule is compiled in, not looked up: the loop's `laws` constant (edmd.c) chooses the
 * constant-xi rule (GR_RULE_CONSTANT: no law code at all), the law rule (GR_RULE_LAW) or
 * the rough rule (GR_RULE_ROUGH: the law rule's normal part, then a tangential impulse
 * and spins, rule_rough_apply below), so a constant-xi run executes no instruction of
 * another rule.  Each value has its own advance_* in edmd.c.
 *
 * A particle may carry more than position and velocity: a rough rule needs each
 * particle's angular velocity (and moment of inertia).  That state lives in an array of
 * its own in the system (gr_edmd, beside `mass`: n * 3 doubles in 3D, n in 2D, NULL for
 * scenes without it), NOT in the particle record (engine.h: x v t r, one 64-byte line in
 * 3D): every scan loads the records of all its candidates, and a wider record would
 * cost every scene in every scan, where the extra array is touched only by a collision of
 * the rule that uses it.  Under constant velocity (flight.h) an angular velocity does not
 * change in flight, so neither the clock nor the predictions read it; the checkpoint
 * saves the array when it exists (csrc/checkpoint.c). */
#ifndef GR_RULE_H
#define GR_RULE_H

#include <math.h>
#include <stdint.h>

#include "collide.h"
#include "common.h"
#include "edmd.h"
#include "restitution.h"
#include "schedstate.h"

/* The values of the loop's compile-time `laws` (edmd.c): bit 0 compiles the law code in
 * (rule_pair_eps, rule_wall_eps), bit 1 the rough rule's tangential impulse and spins. */
#define GR_RULE_CONSTANT 0
#define GR_RULE_LAW 1
#define GR_RULE_ROUGH 3
#define GR_RULE_IS_ROUGH(laws) (((laws) & 2) != 0)

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

/* ---- the rough rule: tangential restitution and spins ----
 *
 * Rough disks and spheres (Huthmann & Zippelius 1997, PRE 56, R6275; Luding, Huthmann,
 * McNamara & Zippelius 1998, PRE 58, 3416, sect. II), written here for unequal
 * radii a_i, a_j and masses, moments of inertia I = q m a^2.  With n = dr / |dr| (from i
 * to j), the relative velocity of j's surface against i's at the contact point is
 *     g = v_j - v_i - (a_i w_i + a_j w_j) x n,
 * with tangential part g_t = g - (g . n) n.  The normal impulse is the smooth one
 * (gr_pair_collide, the same bits: xi, a law or the TC model as for smooth particles);
 * the tangential impulse P_t on j (-P_t on i) turns g_t into -beta g_t:
 *     P_t = -(1 + beta) m_t g_t,   1/m_t = (1 + 1/q) (1/m_i + 1/m_j)
 * (a_i^2 / I_i = 1 / (q m_i)), and the spins change by the impulse's torque about each
 * centre:  w_i -= n x P_t / (q m_i a_i),  w_j -= n x P_t / (q m_j a_j).
 * beta = -1 is smooth (no tangential impulse), beta = 1 keeps the energy; the loss is
 *     dE = -(1 - xi^2) m_eff (g . n)^2 / 2 - (1 - beta^2) m_t |g_t|^2 / 2,
 * m_eff = m_i m_j / (m_i + m_j).  The impulse acts at the contact point, so the angular
 * momentum about that point is kept.
 *
 * Walton's Coulomb rule (Walton & Braun 1986, J. Rheol. 30, 949; measured by Foerster,
 * Louge, Chang & Allia 1994, Phys. Fluids 6, 1108): the tangential impulse sticks
 * (beta = beta_0) while it stays within mu times the normal one, |P_t| <= mu |P_n|, and
 * slides at |P_t| = mu |P_n| beyond, which is the tangential restitution
 *     beta = -1 + mu (1 + xi) (m_eff / m_t) |g . n| / |g_t|
 *          = -1 + mu (1 + xi) (1 + 1/q) cot(gamma)
 * (gamma the angle between g and -n, as Luding et al. 1998 write it for equal particles): beta
 * is the smaller of the two.  friction = mu = +inf is the constant-beta rule.
 *
 * In 2D a spin is the scalar w along z: w x n = w (-n_y, n_x), n x P = n_x P_y - n_y P_x. */

/* The tangential impulse of a pair that has just had its normal impulse of size pn
 * (>= 0): vi, vj, spins wi, wj (1 double in 2D, 3 in 3D) changed in place.  beta the
 * tangential restitution (beta_0 under the Coulomb rule), mu the friction coefficient
 * (+inf: none), q the inertia factor.  Returns the energy it dissipated: P_t = -f g_t
 * turns g_t into (1 - f / m_t) g_t, and the energy changes by P_t . (g_t + g_t') / 2, so
 * the loss is f |g_t|^2 (1 - f / (2 m_t)) -- (1 - beta^2) m_t |g_t|^2 / 2 when it sticks. */
static inline double rule_rough_tangential(int dim, const double *dr, double *vi, double *vj,
                                         double *wi, double *wj, double mi, double mj,
                                         double ai, double aj, double q, double beta,
                                         double mu, double pn)
{
    double dr2 = 0.0;
    for (int a = 0; a < dim; a++) dr2 += dr[a] * dr[a];
    const double inv = 1.0 / sqrt(dr2);
    double n[3] = {dr[0] * inv, dr[1] * inv, dim == 3 ? dr[2] * inv : 0.0};
    double g[3] = {vj[0] - vi[0], vj[1] - vi[1], dim == 3 ? vj[2] - vi[2] : 0.0};
    if (dim == 2) {
        const double w = ai * wi[0] + aj * wj[0];
        g[0] += w * n[1];
        g[1] -= w * n[0];
    } else {
        const double w[3] = {ai * wi[0] + aj * wj[0], ai * wi[1] + aj * wj[1],
                             ai * wi[2] + aj * wj[2]};
        g[0] -= w[1] * n[2] - w[2] * n[1];
        g[1] -= w[2] * n[0] - w[0] * n[2];
        g[2] -= w[0] * n[1] - w[1] * n[0];
    }
    const double gn = g[0] * n[0] + g[1] * n[1] + g[2] * n[2];
    for (int a = 0; a < 3; a++) g[a] -= gn * n[a];
    const double gt2 = g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    if (!(gt2 > 0.0)) return 0.0; /* no tangential motion at the contact: nothing to do */
    /* 1/m_t = (1 + 1/q)(1/m_i + 1/m_j), written without 1/q (q may be tiny) */
    const double m_t = q / ((1.0 + q) * (1.0 / mi + 1.0 / mj));
    double f = (1.0 + beta) * m_t; /* P_t = -f g_t */
    double ratio = 1.0 + beta;     /* f / m_t, kept apart: m_t underflows to 0 at tiny q */
    if (mu < INFINITY && f * sqrt(gt2) > mu * pn) { /* sliding (then m_t > 0) */
        f = mu * pn / sqrt(gt2);
        ratio = f / m_t;
    }
    double P[3] = {-f * g[0], -f * g[1], -f * g[2]};
    for (int a = 0; a < dim; a++) {
        vi[a] -= P[a] / mi;
        vj[a] += P[a] / mj;
    }
    /* w -= n x P / (q m a): (P / m) / q is a speed of the order of g (P_t carries a factor
     * q), so the order of the divisions keeps every step within float64 at any scale */
    if (dim == 2) {
        const double t = n[0] * P[1] - n[1] * P[0];
        wi[0] -= t / mi / q / ai;
        wj[0] -= t / mj / q / aj;
    } else {
        const double t[3] = {n[1] * P[2] - n[2] * P[1], n[2] * P[0] - n[0] * P[2],
                             n[0] * P[1] - n[1] * P[0]};
        for (int a = 0; a < 3; a++) {
            wi[a] -= t[a] / mi / q / ai;
            wj[a] -= t[a] / mj / q / aj;
        }
    }
    return f * gt2 * (1.0 - 0.5 * ratio);
}

/* The rough pair collision: the smooth normal impulse (rule_pair_apply, so beta = -1
 * gives the smooth rule's velocities bit for bit), then the tangential one.  Returns
 * the virial as rule_pair_apply (the normal impulse's: the tangential one is
 * perpendicular to dr), or -1 if the pair does not approach (nothing changed).  beta =
 * -1 (the TC model's elastic collisions: smooth as well) leaves the spins alone.  *loss
 * gets the energy the collision dissipated, translational and rotational, from the
 * rule's own formulas (not from energies before and after): the normal part
 * (1 - xi^2) m_eff (g . n)^2 / 2 plus the tangential one (rule_rough_tangential). */
static inline double rule_rough_apply(int dim, const double *dr, double *vi, double *vj,
                                      double *wi, double *wj, double mi, double mj,
                                      double ai, double aj, double q, double xi, double beta,
                                      double mu, double *loss)
{
    double b = 0.0, dr2 = 0.0; /* dr . (v_j - v_i), before: the spins add nothing along n */
    for (int a = 0; a < dim; a++) {
        b += dr[a] * (vj[a] - vi[a]);
        dr2 += dr[a] * dr[a];
    }
    const double vir = gr_pair_collide(dim, dr, vi, vj, mi, mj, xi);
    *loss = 0.0;
    if (vir < 0.0) return vir;
    *loss = 0.5 * (1.0 - xi * xi) * (mi * mj / (mi + mj)) * (b * b / dr2);
    if (beta == -1.0) return vir;
    /* the virial is |P_n| |dr| */
    *loss += rule_rough_tangential(dim, dr, vi, vj, wi, wj, mi, mj, ai, aj, q, beta, mu,
                                   vir / sqrt(dr2));
    return vir;
}

#endif
