/* restitution.h -- restitution laws: the coefficient of normal restitution as a function
 * of the normal impact speed v_n = |dv . n|, as plain data (a kind and a few numbers, or a
 * table) so that an engine can copy, check and save it.  No state, no allocation here.
 *
 * A constant restitution is not a law: the engine keeps the number in its config and runs
 * the event loop compiled without laws (edmd.c), so a constant-xi run executes no code of
 * this file.
 *
 * The viscoelastic law (Brilliantov, Spahn, Hertzsch & Poeschel 1996, Phys. Rev. E 53,
 * 5382): spheres with the dissipative Hertz force F = rho (xi^(3/2) + (3/2) A xi^(1/2)
 * dxi/dt), rho = 2 Y sqrt(R_eff) / (3 (1 - nu^2)), restitute with
 *     eps(v) = 1 - C1 A kappa^(2/5) v^(1/5) + C2 A^2 kappa^(4/5) v^(2/5) -+ ...,
 *     kappa = (3/2)^(3/2) Y sqrt(R_eff) / (m_eff (1 - nu^2)),
 *     C1 = Gamma(3/5) sqrt(pi) / (2^(1/5) 5^(2/5) Gamma(21/10)) = 1.15345,  C2 = (3/5) C1^2,
 * (Schwager & Poeschel 1998, Phys. Rev. E 57, 650, the series and C1, C2; Brilliantov &
 * Poeschel, Kinetic Theory of Granular Gases, OUP 2004, ch. 6, the same in this notation;
 * equation numbers not given: the papers' text was not at hand, so the convention was
 * fixed by integrating the contact numerically, see tests/test_restitution.py).  Series
 * of order 2 in delta = A kappa^(2/5) v^(1/5): for a contact that ends where the force
 * vanishes (Schwager & Poeschel 2008, Phys. Rev. E 78, 051304) the next term is
 * +(4/15) delta^(5/2) (checked against a numerical integration of the contact,
 * tests/test_restitution.py), so it is evaluated for delta <= GR_VISCO_DELTA_MAX only,
 * where the error is at most 0.0015 (eps >= 0.76); faster impacts are given eps at
 * delta max and counted (gr_edmd_counters.law_clamped), because the truncated series
 * turns up again past delta = C1 / (2 C2) = 0.72 and means nothing there.  In 2D the same
 * law is a model choice: there is no Hertz law for disks. */
#ifndef GR_RESTITUTION_H
#define GR_RESTITUTION_H

#include <math.h>
#include <stdint.h>

enum {
    GR_LAW_CONSTANT = 0,    /* no law: the config's number */
    GR_LAW_VISCOELASTIC = 1,
    GR_LAW_TABLE = 2        /* linear interpolation in a table (v_k, eps_k) */
};

#define GR_VISCO_C1 1.1534488580952884 /* Gamma(3/5) sqrt(pi) / (2^(1/5) 5^(2/5) Gamma(21/10)) */
#define GR_VISCO_C2 0.7982665609447948 /* (3/5) C1^2 */
#define GR_VISCO_DELTA_MAX 0.25
#define GR_LAW_TABLE_MAX 1000000 /* points: a measured curve needs far fewer */

typedef struct {
    int kind;             /* GR_LAW_* */
    double scale;         /* viscoelastic: A kappa^(2/5) (speed^(-1/5)), > 0 */
    double v_max;         /* viscoelastic: (GR_VISCO_DELTA_MAX / scale)^5, where the
                           * series stops being used */
    int64_t count;        /* table: points, >= 1 */
    const double *speeds; /* table: count, increasing, >= 0 (an engine owns its copy) */
    const double *values; /* table: count, in [0, 1] */
} gr_law;

/* eps at normal impact speed v >= 0; *clamped += 1 if v lies past the viscoelastic
 * series' range.  A table is held constant beyond its ends (as numpy.interp). */
static inline double gr_law_eval(const gr_law *law, double v, int64_t *clamped)
{
    if (law->kind == GR_LAW_VISCOELASTIC) {
        if (v > law->v_max) {
            v = law->v_max;
            ++*clamped;
        }
        double d = law->scale * pow(v, 0.2);
        return 1.0 - d * (GR_VISCO_C1 - GR_VISCO_C2 * d);
    }
    const double *x = law->speeds, *y = law->values;
    int64_t hi = law->count - 1, lo = 0;
    if (!(v > x[0])) return y[0];
    if (!(v < x[hi])) return y[hi];
    while (hi - lo > 1) { /* x[lo] < v < x[hi] */
        int64_t mid = lo + (hi - lo) / 2;
        if (x[mid] <= v) lo = mid;
        else hi = mid;
    }
    double slope = (y[hi] - y[lo]) / (x[hi] - x[lo]);
    return slope * (v - x[lo]) + y[lo];
}

#endif
