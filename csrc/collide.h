/* collide.h -- two-body geometry of hard spheres: when do two spheres on straight lines
 * touch, and what are their velocities afterwards.  No queue, no cells, no state.
 *
 * Header-only so that the compiler inlines and unrolls these for a fixed dimension
 * (they run inside the innermost loop of the event-driven engine). */
#ifndef GR_COLLIDE_H
#define GR_COLLIDE_H

#include <math.h>

/* gr_pair_beats' cheap test, on b = dr . dv, c = |dr|^2 - sigma^2 and disc = b^2 - |dv|^2 c:
 * approaching, and touching already or possibly before `horizon` (the root is at least
 * c / (-2 b)).  False for a pair that cannot touch before it; the root decides the rest.
 * The tests are combined without branches (see gr_pair_beats). */
static inline int gr_pair_may_beat(double b, double c, double disc, double horizon)
{
    const int touching = c <= 0.0;
    const int soon = (c < -2.0 * b * horizon) & (disc > 0.0);
    return (b < 0.0) & (touching | soon);
}

/* Whether two spheres on straight lines touch before `horizon`, given their separation
 * dr = x_j - x_i, relative velocity dv = v_j - v_i and contact distance sigma (thesis
 * 2.16-2.20); if so, *dt is the time until they touch.
 *
 * Robust to rounding: a pair that already touches or overlaps (|dr| <= sigma) and
 * approaches collides at once (dt = 0), so an overlap produced by rounding can never
 * grow.  The root is taken in the cancellation-free form c / (-b + sqrt(b^2 - a c)).
 * Shaped for the scan over candidates, where nearly every pair fails: the tests
 * (approaching? touching, or soon enough -- dt >= c / (-2b) -- and not missing?) are
 * combined without branches, so that the one branch per candidate is almost always "no"
 * and well predicted; separate early exits each go either way about half the time, and
 * mispredicting them costs more than the arithmetic they skip. */
static inline int gr_pair_beats(int dim, const double *dr, const double *dv, double sigma,
                                double horizon, double *dt)
{
    /* sums started from the first terms, not from 0.0: without -ffast-math the compiler
     * must keep an addition of 0.0 (it turns -0.0 into +0.0), three more instructions
     * for every candidate of every scan */
    double b = dr[0] * dv[0], dr2 = dr[0] * dr[0], dv2 = dv[0] * dv[0];
    for (int a = 1; a < dim; a++) {
        b += dr[a] * dv[a];
        dr2 += dr[a] * dr[a];
        dv2 += dv[a] * dv[a];
    }
    double c = dr2 - sigma * sigma;
    double disc = b * b - dv2 * c;
    if (!gr_pair_may_beat(b, c, disc, horizon)) return 0;
    double t = c <= 0.0 ? 0.0 : c / (-b + sqrt(disc));
    *dt = t;
    return t < horizon;
}

/* Apply the collision rule (thesis 2.10-2.11) to v_i and v_j in place, for separation
 * dr = x_j - x_i at contact, masses m_i, m_j and restitution xi.  |dr| is used rather
 * than the contact distance so that rounding in the contact position cannot bias the
 * impulse.  Returns the virial dr . dp_j (>= 0), or -1 if the pair does not approach
 * (then nothing changes). */
static inline double gr_pair_collide(int dim, const double *dr, double *vi, double *vj,
                                     double mi, double mj, double xi)
{
    double b = 0.0, dr2 = 0.0;
    for (int a = 0; a < dim; a++) {
        b += dr[a] * (vj[a] - vi[a]);
        dr2 += dr[a] * dr[a];
    }
    if (!(b < 0.0) || !(dr2 > 0.0)) return -1.0;
    double f = (1.0 + xi) * b / (dr2 * (mi + mj));
    for (int a = 0; a < dim; a++) {
        vi[a] += f * mj * dr[a];
        vj[a] -= f * mi * dr[a];
    }
    return -f * mi * mj * dr2;
}

#endif
