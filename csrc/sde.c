/* sde.c -- Euler-Maruyama and exact integration of the underdamped Langevin equation and
 * of UDSBM (see sde.h), with the ensemble MSD and the time-averaged MSD accumulated on
 * the fly.
 *
 * Each particle is independent, so the loop runs over particles outside and steps
 * inside: a particle's state stays in registers for the whole run, and the TAMSD needs
 * only the rings of one particle's past positions at a time (tamsd.h: O(levels) memory,
 * not O(N x steps)).  The particles are split over threads by blocks (sde.h).
 * Invariant: a particle's random numbers depend only on (key, step, particle), never on
 * the order of work -- nor on how many steps' worth are drawn at once: a particle's
 * normals are drawn GR_NORMAL_BATCH steps ahead (rng.h's gr_normal_batch, vectorised),
 * each the very number gr_normal would draw in its step's stream, and the update reads
 * them in the same order, so the bits are those of drawing step by step. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "rng.h"
#include "sde.h"
#include "tamsd.h"

/* x-noise variance of the exact step in units of D/gamma, minus the part explained by the
 * velocity noise: g(h) = 2 f(h) - (1-c)^3/(1+c), c = exp(-h), with
 * f(h) = h - 2(1-c) + (1-c^2)/2.  A series for small h, where the terms cancel. */
static double exact_gxx(double h)
{
    if (h < 1e-2) return h * h * h * (1.0 / 6.0 - h * h / 60.0);
    double omc = -expm1(-h), c = 1.0 - omc;
    double f = h - 2.0 * omc - 0.5 * expm1(-2.0 * h);
    return 2.0 * f - omc * omc * omc / (1.0 + c);
}

/* Per-step coefficients of the exact update for friction g and diffusivity D. */
typedef struct {
    double c, drift, sv, kx, sx;
} exact_coef;

static exact_coef exact_for(double g, double D, double dt)
{
    exact_coef e;
    double h = g * dt, omc = -expm1(-h);
    e.c = 1.0 - omc;
    e.drift = omc / g;                              /* x += v (1 - c)/gamma */
    double vv = -D * g * expm1(-2.0 * h);           /* Var(v noise) = D gamma (1 - c^2) */
    e.sv = sqrt(vv);
    double cxv = D * omc * omc;                     /* Cov(x noise, v noise) */
    e.kx = vv > 0.0 ? cxv / e.sv : 0.0;
    double rest = D / g * exact_gxx(h);
    e.sx = rest > 0.0 ? sqrt(rest) : 0.0;
    return e;
}

/* UDSBM's decay factor (1 + t/tau0)^-a from w = 1 + t/tau0.  a = 1 divides, as the
 * thesis' UDSBM always did, so its results stay the same to the bit. */
static inline double udsbm_decay(double w, double a)
{
    return a == 1.0 ? 1.0 / w : pow(w, -a);
}

/* The exact step of one axis under a linear force per mass f(X) = g - w (X - c), w >= 0,
 * written with the force at the start of the step, f0 = g - w (X0 - c):
 *   X1 = X0 + e12 v0 + j1 f0 + kx z1 + sx z2,   v1 = e22 v0 + e12 f0 + sv z1,
 * where E(t) = exp(A t), A = [[0, 1], [-w, -gamma]], propagates the mean (e12, e22 its
 * second column) and J(t) = int_0^t E(s) e2 ds (j1 its first entry) the force's share:
 * the mean is E (X0 - c, v0) + J (g + w c) around c, and E - I = (int_0^t E) A gives
 * e11 - 1 = -w j1, e21 = -w e12, hence the form above.  The noise covariance is the
 * Lyapunov integral
 *   S(t) = sigma^2 int_0^t E(s) e2 e2^T E(s)^T ds,   sigma^2 = 2 D gamma^2,
 * sampled with the velocity first (sv^2 = S_vv, kx = S_xv / sv, sx^2 = S_xx - kx^2).
 * One method for every regime (underdamped w > gamma^2/4, critical, overdamped, w = 0):
 * a Taylor series on a step short against both rates (r t <= 1/4, r = max(gamma,
 * sqrt(w))), then doubling k times,
 *   E(2t) = E(t)^2,  J(2t) = J(t) + E(t) J(t),  S(2t) = S(t) + E(t) S(t) E(t)^T,
 * whose terms, at short times, are all non-negative: no division, no cancellation between
 * the damping regimes, and S_xx (~ sigma^2 t^3/3) keeps its relative precision however
 * small the step.  Once per run (the coefficients are constant), so its cost is nothing. */
typedef struct {
    double e12, e22, j1, kx, sx, sv;
} force_coef;

static force_coef force_exact_for(double g, double D, double w, double dt)
{
    const double r = g > sqrt(w) ? g : sqrt(w);
    double t = dt;
    int k = 0;
    while (r * t > 0.25 && k < 4096) { /* at most ~950 halvings for the scales run allows */
        t *= 0.5;
        k++;
    }
    /* Taylor: M_n = (A t)^n / n!, E = sum M_n, J = t sum M_n e2 / (n+1); u_n = M_n e2 is
     * the series of E(s) e2 in (s/t)^n, so S_ab = sigma^2 t sum_{n,m} u_n,a u_m,b / (n+m+1).
     * 20 terms: the scaled norm of A t is at most 1/2, the remainder < 0.5^20/20!. */
    enum { NT = 20 };
    double m11 = 1, m12 = 0, m21 = 0, m22 = 1;
    double e11 = 0, e12 = 0, e21 = 0, e22 = 0, j1 = 0, j2 = 0, u1[NT], u2[NT];
    for (int n = 0; n < NT; n++) {
        if (n > 0) { /* M_n = M_{n-1} (A t) / n */
            const double a11 = -m12 * w * t, a12 = (m11 - m12 * g) * t;
            const double a21 = -m22 * w * t, a22 = (m21 - m22 * g) * t;
            m11 = a11 / n, m12 = a12 / n, m21 = a21 / n, m22 = a22 / n;
        }
        e11 += m11, e12 += m12, e21 += m21, e22 += m22;
        j1 += m12 / (n + 1), j2 += m22 / (n + 1);
        u1[n] = m12, u2[n] = m22;
    }
    j1 *= t, j2 *= t;
    const double sig2 = 2.0 * D * g * g;
    double sxx = 0, sxv = 0, svv = 0;
    for (int n = NT - 1; n >= 0; n--) /* smallest terms first */
        for (int m = NT - 1; m >= 0; m--) {
            const double c = 1.0 / (n + m + 1);
            sxx += u1[n] * u1[m] * c, sxv += u1[n] * u2[m] * c, svv += u2[n] * u2[m] * c;
        }
    sxx *= sig2 * t, sxv *= sig2 * t, svv *= sig2 * t;
    for (int i = 0; i < k; i++) {
        /* S + E S E^T, with E S first */
        const double p11 = e11 * sxx + e12 * sxv, p12 = e11 * sxv + e12 * svv;
        const double p21 = e21 * sxx + e22 * sxv, p22 = e21 * sxv + e22 * svv;
        const double nxx = sxx + (p11 * e11 + p12 * e12);
        const double nxv = sxv + (p11 * e21 + p12 * e22);
        const double nvv = svv + (p21 * e21 + p22 * e22);
        sxx = nxx, sxv = nxv, svv = nvv;
        const double nj1 = j1 + (e11 * j1 + e12 * j2), nj2 = j2 + (e21 * j1 + e22 * j2);
        j1 = nj1, j2 = nj2;
        const double f11 = e11 * e11 + e12 * e21, f12 = e11 * e12 + e12 * e22;
        const double f21 = e21 * e11 + e22 * e21, f22 = e21 * e12 + e22 * e22;
        e11 = f11, e12 = f12, e21 = f21, e22 = f22;
    }
    force_coef f;
    f.e12 = e12;
    f.e22 = e22;
    f.j1 = j1;
    f.sv = svv > 0.0 ? sqrt(svv) : 0.0;
    f.kx = f.sv > 0.0 ? sxv / f.sv : 0.0;
    const double rest = sxx - f.kx * f.kx;
    f.sx = rest > 0.0 ? sqrt(rest) : 0.0;
    return f;
}

void gr_sde_force_step(double gamma, double D, double w, double dt, double out[6])
{
    const force_coef f = force_exact_for(gamma, D, w, dt);
    out[0] = f.e12, out[1] = f.e22, out[2] = f.j1, out[3] = f.kx, out[4] = f.sx, out[5] = f.sv;
}

/* Euler-Maruyama in a trap, x1 = x0 + v0 dt, v1 = (1 - gamma dt) v0 - w dt x0 + noise, is
 * the linear map [[1, dt], [-w dt, 1 - gamma dt]] on the mean (and its Kronecker square on
 * the covariance).  Its eigenvalues solve mu^2 - (2 - gamma dt) mu + 1 - gamma dt + w dt^2
 * = 0, inside the unit circle (Jury) iff |1 - gamma dt + w dt^2| < 1 and
 * 4 - 2 gamma dt + w dt^2 > 0: with gamma dt < 2 (refused otherwise), iff w dt < gamma. */
static int em_trap_stable(double g, double w, double dt)
{
    return w * dt < g;
}

/* What one step needs besides the particle's state. */
typedef struct {
    uint64_t key;
    double dt, g0, D0, tau0, b0, expo;
    int udsbm, em;
    exact_coef ex0;
    const exact_coef *table; /* the exact scheme's UDSBM coefficients per step, or NULL */
    int64_t table_from;      /* the step that table[0] and em_table[0] start from */
    const double *em_table;  /* Euler-Maruyama's (1 - gamma dt, sqrt(2 D dt) gamma) per step
                                for an exponent != 1 (a pow a step saved per particle), or NULL */
    const struct force_params *force; /* external forces (run_steps_force), or NULL; apart,
                                         so that the force-free loop's data stay as they were */
} step_params;

/* The external force's per-axis data. */
typedef struct force_params {
    double accel[3], stiffness[3];
    force_coef fc[3]; /* the exact scheme's */
} force_params;

/* A particle's normals drawn ahead (rng.h's gr_normal_batch): z[k * GR_NORMAL_BATCH + j]
 * is the k-th normal of step first + j (the stream (key, first + j - 1, i)). */
typedef struct {
    int64_t first;
    double z[GR_NORMAL_BATCH_MAX_M * GR_NORMAL_BATCH];
} normals_ahead;

/* Steps from+1 .. to of particle i (the step numbered k goes from t = (k-1) dt to k dt and
 * draws the randoms of (key, k-1, i)), its normals from `ahead`, refilled for the next
 * GR_NORMAL_BATCH steps whenever a step is past them (steps only go forward, and the
 * buffer lives as long as the particle's run, across bookkeeping stops).  Each normal is
 * the very number gr_normal would draw at that point of the step's stream, so the
 * update, unchanged, gives the same bits as drawing step by step.  Always inlined with a
 * constant d, so that each dimension gets its own unrolled loop. */
#if defined(__GNUC__) || defined(__clang__)
#define GR_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define GR_ALWAYS_INLINE inline
#endif

static GR_ALWAYS_INLINE void run_steps(const int d, const step_params *p, int64_t i,
                                       int64_t from, int64_t to, double *xi, double *vi,
                                       normals_ahead *ahead)
{
    const double dt = p->dt;
    const int m = p->em ? d : 2 * d; /* normals a step */
    for (int64_t step = from + 1; step <= to; step++) {
        if (step - ahead->first >= GR_NORMAL_BATCH) {
            ahead->first = step;
            gr_normal_batch(p->key, (uint64_t)(step - 1), (uint64_t)i, m, ahead->z);
        }
        const double *z = ahead->z + (step - ahead->first); /* z[k B]: the k-th normal */
        if (p->em) {
            double a_coef = 1.0 - p->g0 * dt, b = p->b0;
            if (p->em_table) {
                a_coef = p->em_table[2 * (step - 1 - p->table_from)];
                b = p->em_table[2 * (step - 1 - p->table_from) + 1];
            } else if (p->udsbm) { /* gamma(t_n), D(t_n) at the start of the step (2.110) */
                const double t = (double)(step - 1) * dt;
                double s = udsbm_decay(1.0 + t / p->tau0, p->expo);
                a_coef = 1.0 - p->g0 * s * dt;
                b = p->b0 * s * sqrt(s);
            }
            for (int a = 0; a < d; a++) {
                const double za = z[a * GR_NORMAL_BATCH];
                xi[a] += vi[a] * dt;
                vi[a] = a_coef * vi[a] + b * za;
            }
        } else {
            exact_coef e = p->ex0;
            if (p->table) {
                e = p->table[step - 1 - p->table_from];
            } else if (p->udsbm) { /* coefficients frozen at the midpoint of the step,
                                    * computed exactly as the table does */
                const double w = 1.0 + ((double)(step - 1) + 0.5) * dt / p->tau0;
                double s = udsbm_decay(w, p->expo);
                e = exact_for(p->g0 * s, p->D0 * s, dt);
            }
            for (int a = 0; a < d; a++) { /* per axis: z1 drives v, z2 the rest of x */
                const double z1 = z[2 * a * GR_NORMAL_BATCH], z2 = z[(2 * a + 1) * GR_NORMAL_BATCH];
                xi[a] += vi[a] * e.drift + e.kx * z1 + e.sx * z2;
                vi[a] = e.c * vi[a] + e.sv * z1;
            }
        }
    }
}

/* run_steps with external forces (Langevin model only): the same normals in the same
 * order, the force per mass f = g - w (X - c) at the start of each step, X - c = o + x
 * from the particle's start o relative to the trap's centre. */
static GR_ALWAYS_INLINE void run_steps_force(const int d, const step_params *p, int64_t i,
                                             int64_t from, int64_t to, double *xi, double *vi,
                                             const double *oi, normals_ahead *ahead)
{
    const double dt = p->dt;
    const int m = p->em ? d : 2 * d;
    for (int64_t step = from + 1; step <= to; step++) {
        if (step - ahead->first >= GR_NORMAL_BATCH) {
            ahead->first = step;
            gr_normal_batch(p->key, (uint64_t)(step - 1), (uint64_t)i, m, ahead->z);
        }
        const double *z = ahead->z + (step - ahead->first);
        const force_params *fp = p->force;
        if (p->em) {
            const double a_coef = 1.0 - p->g0 * dt, b = p->b0;
            for (int a = 0; a < d; a++) {
                const double f = fp->accel[a] - fp->stiffness[a] * (oi[a] + xi[a]);
                xi[a] += vi[a] * dt;
                vi[a] = a_coef * vi[a] + f * dt + b * z[a * GR_NORMAL_BATCH];
            }
        } else {
            for (int a = 0; a < d; a++) {
                const force_coef e = fp->fc[a];
                const double z1 = z[2 * a * GR_NORMAL_BATCH], z2 = z[(2 * a + 1) * GR_NORMAL_BATCH];
                const double f = fp->accel[a] - fp->stiffness[a] * (oi[a] + xi[a]);
                xi[a] += vi[a] * e.e12 + f * e.j1 + e.kx * z1 + e.sx * z2;
                vi[a] = e.e22 * vi[a] + e.e12 * f + e.sv * z1;
            }
        }
    }
}

/* run_steps_force for each dimension, kept out of run_particle (never inlined there) so
 * that the force-free loop is compiled as it was without forces. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((noinline))
#endif
static void steps_force(const int d, const step_params *p, int64_t i, int64_t from, int64_t to,
                        double *xi, double *vi, const double *oi, normals_ahead *ahead)
{
    switch (d) {
    case 1: run_steps_force(1, p, i, from, to, xi, vi, oi, ahead); break;
    case 2: run_steps_force(2, p, i, from, to, xi, vi, oi, ahead); break;
    default: run_steps_force(3, p, i, from, to, xi, vi, oi, ahead); break;
    }
}

/* The first sample at or after a step (binary search: sample_steps increase). */
static int64_t first_sample_from(const gr_sde_output *out, int64_t step)
{
    int64_t lo = 0, hi = out->n_samples;
    while (lo < hi) {
        const int64_t mid = lo + (hi - lo) / 2;
        if (out->sample_steps[mid] < step) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* Everything one particle's run over the call's segment reads or writes besides its own
 * state: shared read-only setup, and the scratch and sums of the thread that runs it. */
typedef struct {
    const gr_sde_config *cfg;
    const step_params *sp;
    const gr_sde_output *out;
    const gr_tamsd_plan *plan;
    int64_t n, step_from, step_to, n_steps, ks0;
} run_shared;

/* The TAMSD's bookkeeping at step t of a particle at xi (tamsd.h): first the windows
 * ending at t, read from the rings (before t's own stores, which may reuse a slot), then
 * the stores of the levels whose stride divides t. */
static GR_ALWAYS_INLINE void tamsd_book(const int d, const gr_tamsd_plan *p, int64_t t,
                                        const double *xi, double *ring, double *acc,
                                        int64_t *slow_next, int64_t *next_slow)
{
    /* stride 1: the first n_every lags, ascending, at every step once t reaches them */
    const double *r0 = ring; /* level 0's ring comes first */
    for (int64_t l = 0; l < p->n_every && p->lag[l].lag <= t; l++) {
        const double *old = r0 + ((t - p->lag[l].lag) & p->lag[l].mask) * d;
        double sum = 0.0;
        for (int a = 0; a < d; a++) sum += (xi[a] - old[a]) * (xi[a] - old[a]);
        acc[l] += sum;
    }
    const int64_t ph = t & p->phase_mask;
    for (int64_t k = p->phase_off[ph]; k < p->phase_off[ph + 1]; k++) {
        const int64_t l = p->phase_lag[k];
        const gr_tamsd_lag g = p->lag[l];
        if (t < g.lag) continue; /* the window would start before step 0 */
        const double *old = ring + g.off + (((t - g.lag) >> g.level) & g.mask) * d;
        double sum = 0.0;
        for (int a = 0; a < d; a++) sum += (xi[a] - old[a]) * (xi[a] - old[a]);
        acc[l] += sum;
    }
    if (t == *next_slow) {
        int64_t soonest = INT64_MAX;
        for (int64_t j = 0; j < p->n_slow; j++) {
            const gr_tamsd_lag g = p->lag[p->slow[j]];
            if (slow_next[j] == t) {
                const double *old = ring + g.off + (((t - g.lag) >> g.level) & g.mask) * d;
                double sum = 0.0;
                for (int a = 0; a < d; a++) sum += (xi[a] - old[a]) * (xi[a] - old[a]);
                acc[p->slow[j]] += sum;
                slow_next[j] += (int64_t)1 << g.level;
            }
            if (slow_next[j] < soonest) soonest = slow_next[j];
        }
        *next_slow = soonest;
    }
    /* level e stores at multiples of 2^e: levels 0 .. (trailing zeros of t) */
    for (int e = 0; e <= p->top && (e == 0 || (t & (((int64_t)1 << e) - 1)) == 0); e++)
        if (p->used >> e & 1)
            memcpy(ring + p->level_off[e] + ((t >> e) & p->level_mask[e]) * d, xi,
                   (size_t)d * sizeof(double));
}

/* Particle i over the segment: x, v its state (d values each) in and out; the samples'
 * squares are added to x2, v2 (n_samples x d each: its block's sums), its TAMSD windows
 * to out->tamsd; ring and slow_next (a step per slow lag) are the running thread's
 * scratch (the ring carries over between segments).  Returns GR_OK or GR_ERR_NONFINITE. */
static int run_particle(const run_shared *rs, int64_t i, double *x, double *v,
                        const double *o, double *x2, double *v2, double *ring,
                        int64_t *slow_next)
{
    const gr_sde_output *out = rs->out;
    const int d = rs->cfg->dim;
    const int64_t n = rs->n, step_from = rs->step_from, step_to = rs->step_to;
    const int64_t n_steps = rs->n_steps;
    double xi[3] = {0, 0, 0}, vi[3] = {0, 0, 0}, oi[3] = {0, 0, 0};
    for (int a = 0; a < d; a++) {
        xi[a] = x[a];
        vi[a] = v[a];
        if (o) oi[a] = o[a];
    }
    int64_t ks = rs->ks0;
    normals_ahead ahead;
    ahead.first = -GR_NORMAL_BATCH; /* none yet: the first step fills it */
    const gr_tamsd_plan *tp = rs->plan;
    double *acc = out->tamsd + i * tp->n_lags; /* the particle's window sums, in time order */
    /* the slow lags' next window ends after step_from: k + j s >= step_from */
    int64_t next_slow = INT64_MAX;
    for (int64_t j = 0; j < tp->n_slow; j++) {
        const int64_t lag = tp->lag[tp->slow[j]].lag, s = (int64_t)1 << tp->lag[tp->slow[j]].level;
        slow_next[j] = step_from <= lag ? lag : lag + ((step_from - lag - 1) / s + 1) * s;
        if (slow_next[j] < next_slow) next_slow = slow_next[j];
    }
    /* Bookkeeping (samples, TAMSD windows) happens at the steps that need it; between
     * them the particle is stepped in a tight loop.  Step 0, the start, is a sample and a
     * window start for every lag. */
    for (int64_t step = step_from;;) {
        if (step == step_to && step_to < n_steps) break; /* booked by the next segment */
        while (ks < out->n_samples && out->sample_steps[ks] == step) {
            for (int a = 0; a < d; a++) {
                x2[ks * d + a] += xi[a] * xi[a];
                v2[ks * d + a] += vi[a] * vi[a];
                if (out->positions) out->positions[(ks * n + i) * d + a] = xi[a];
            }
            ks++;
        }
        int64_t next = step_to; /* the next step that needs bookkeeping */
        if (ks < out->n_samples && out->sample_steps[ks] < next) next = out->sample_steps[ks];
        if (tp->n_lags) {
            switch (d) {
            case 1: tamsd_book(1, tp, step, xi, ring, acc, slow_next, &next_slow); break;
            case 2: tamsd_book(2, tp, step, xi, ring, acc, slow_next, &next_slow); break;
            default: tamsd_book(3, tp, step, xi, ring, acc, slow_next, &next_slow); break;
            }
            const int64_t busy = step + 1 + tp->gap[(step + 1) & tp->phase_mask];
            if (busy < next) next = busy;
            if (next_slow < next) next = next_slow;
        }
        if (step == n_steps) break;
        /* steps step+1 .. next, each with its own dimension so that the axis loops
         * unroll */
        if (rs->sp->force) {
            steps_force(d, rs->sp, i, step, next, xi, vi, oi, &ahead);
        } else {
            switch (d) {
            case 1: run_steps(1, rs->sp, i, step, next, xi, vi, &ahead); break;
            case 2: run_steps(2, rs->sp, i, step, next, xi, vi, &ahead); break;
            default: run_steps(3, rs->sp, i, step, next, xi, vi, &ahead); break;
            }
        }
        step = next;
    }
    for (int a = 0; a < d; a++) {
        if (!isfinite(xi[a]) || !isfinite(vi[a])) return GR_ERR_NONFINITE;
        x[a] = xi[a];
        v[a] = vi[a];
    }
    return GR_OK;
}

/* One thread's share of a call: particles [lo, hi) (whole blocks, but for the call's
 * first and last), their sample sums into the blocks' rows of `sums`. */
typedef struct {
    const run_shared *rs;
    int64_t lo, hi;       /* global particle indices */
    int64_t first;        /* the call's first particle: x, v and sums start there */
    double *x, *v;        /* the call's state arrays */
    double *sums;         /* the call's block sums, row 0 for the block of `first` */
    double *ring;         /* this thread's scratch */
    int64_t *slow_next;
    int status;
    int64_t bad;          /* the particle that failed, or -1 */
} worker;

static void *work(void *arg)
{
    worker *w = arg;
    const int d = w->rs->cfg->dim;
    const int64_t row = 2 * w->rs->out->n_samples * d, b0 = w->first / GR_SDE_BLOCK;
    w->status = GR_OK;
    w->bad = -1;
    for (int64_t i = w->lo; i < w->hi; i++) {
        double *s = w->sums + (i / GR_SDE_BLOCK - b0) * row;
        const int64_t at = (i - w->first) * d;
        const double *o = w->rs->cfg->origin ? w->rs->cfg->origin + at : NULL;
        int st = run_particle(w->rs, i, w->x + at, w->v + at, o, s,
                              s + w->rs->out->n_samples * d, w->ring, w->slow_next);
        if (st != GR_OK) {
            w->status = st;
            w->bad = i;
            break;
        }
    }
    return NULL;
}

int gr_sde_run(const gr_sde_config *cfg, int64_t n, int64_t first, int64_t count,
               int64_t step_from, int64_t step_to, int64_t n_steps, double *x, double *v,
               gr_sde_output *out, int threads, gr_error *err)
{
    const int d = cfg->dim;
    const double dt = cfg->dt, g0 = cfg->gamma0, D0 = cfg->D0, tau0 = cfg->tau0;
    const double expo = cfg->exponent;
    const int udsbm = cfg->model == GR_SDE_UDSBM;
    const int whole = step_from == 0 && step_to == n_steps;
    if (d < 1 || d > 3 || !(dt > 0.0) || !(g0 > 0.0) || !(D0 > 0.0) || !(tau0 > 0.0) ||
        !(expo > 0.0 && expo < INFINITY) || n_steps < 0 || n_steps > GR_SDE_MAX_STEPS ||
        step_from < 0 || step_from > step_to ||
        step_to > n_steps || first < 0 || count < 0 || first > n || count > n - first ||
        (!whole && count > 1) || threads < 1 || out->n_samples < 0 ||
        out->n_samples > INT64_MAX / 6) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, NAN, "invalid SDE parameters");
        return GR_ERR_VALUE;
    }
    if (cfg->force) {
        int bad = udsbm;
        for (int a = 0; a < d; a++)
            bad |= !isfinite(cfg->accel[a]) || !(cfg->stiffness[a] >= 0.0) ||
                   !(cfg->stiffness[a] < INFINITY);
        if (bad) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, NAN,
                         "external forces need the Langevin model, finite accelerations and "
                         "finite stiffnesses >= 0");
            return GR_ERR_VALUE;
        }
    }
    if (cfg->scheme == GR_SDE_EM && g0 * dt >= 2.0) {
        gr_error_set(err, GR_ERR_UNSTABLE, -1, -1, NAN, g0 * dt,
                     "Euler-Maruyama diverges for gamma0*dt >= 2; take a smaller dt or the "
                     "exact scheme (scheme='exact'), stable at any step");
        return GR_ERR_UNSTABLE;
    }
    if (cfg->force && cfg->scheme == GR_SDE_EM)
        for (int a = 0; a < d; a++)
            if (!em_trap_stable(g0, cfg->stiffness[a], dt)) {
                gr_error_set(err, GR_ERR_UNSTABLE, -1, -1, NAN, cfg->stiffness[a] * dt / g0,
                             "Euler-Maruyama in a harmonic trap diverges for (k/m) dt >= gamma0; "
                             "take a smaller dt or the exact scheme (scheme='exact'), stable "
                             "at any step");
                return GR_ERR_UNSTABLE;
            }
    if (count == 0) return GR_OK;
    if (!gr_rng_ready) gr_rng_init();
    const double sq_dt = sqrt(dt), b0 = sqrt(2.0 * D0) * g0 * sq_dt;
    const exact_coef ex0 = exact_for(g0, D0, dt);
    exact_coef *table = NULL;
    if (udsbm && cfg->scheme == GR_SDE_EXACT && out->step_coef) {
        table = (exact_coef *)out->step_coef;
        for (int64_t st = step_from; st < step_to; st++) {
            double s = udsbm_decay(1.0 + ((double)st + 0.5) * dt / tau0, cfg->exponent);
            table[st - step_from] = exact_for(g0 * s, D0 * s, dt);
        }
    }
    /* EM's coefficients per step, computed exactly as inline; only for an exponent != 1,
     * whose pow would otherwise be paid per particle and step (a = 1 divides, as cheap as
     * the table, and stays as it was) */
    double *em_table = NULL;
    if (udsbm && cfg->scheme == GR_SDE_EM && expo != 1.0 && out->step_coef) {
        em_table = out->step_coef;
        for (int64_t st = step_from; st < step_to; st++) {
            double s = udsbm_decay(1.0 + (double)st * dt / tau0, expo);
            em_table[2 * (st - step_from)] = 1.0 - g0 * s * dt;
            em_table[2 * (st - step_from) + 1] = b0 * s * sqrt(s);
        }
    }

    force_params fp;
    memset(&fp, 0, sizeof fp);
    if (cfg->force)
        for (int a = 0; a < d; a++) {
            fp.accel[a] = cfg->accel[a];
            fp.stiffness[a] = cfg->stiffness[a];
            if (cfg->scheme == GR_SDE_EXACT) fp.fc[a] = force_exact_for(g0, D0, cfg->stiffness[a], dt);
        }
    const step_params sp = {cfg->key, dt, g0, D0, tau0, b0, expo, udsbm, cfg->scheme == GR_SDE_EM,
                            ex0, table, step_from, em_table, cfg->force ? &fp : NULL};

    /* The ensemble sums, the same bits for any split: each block of GR_SDE_BLOCK particles
     * (by global index) sums its particles in index order from zero (or from the carry a
     * previous call left for a block it began), and complete blocks are added to x2, v2
     * in block order after every thread is done.  A thread takes whole blocks. */
    const int64_t T = out->n_samples, row = 2 * T * d;
    const int64_t b_first = first / GR_SDE_BLOCK, b_last = (first + count - 1) / GR_SDE_BLOCK;
    const int64_t nb = b_last - b_first + 1;
    const int64_t nt = threads < nb ? threads : nb;
    /* scratch per extra thread: its ring and slow lags' steps (thread 0 has out's ring) */
    const int64_t ring_n = gr_tamsd_ring_size(d, out->n_lags, out->lags, out->estimator);
    if (ring_n < 0 || (row > 0 && nb > (int64_t)(SIZE_MAX / sizeof(double) / 2) / row) ||
        (nt > 1 && ring_n > (int64_t)(SIZE_MAX / sizeof(double) / 2) / (nt - 1))) {
        gr_error_set(err, GR_ERR_NOMEM, -1, -1, NAN, NAN, "the SDE scratch's size overflows");
        return GR_ERR_NOMEM;
    }
    gr_tamsd_plan plan;
    if (gr_tamsd_plan_init(&plan, d, out->n_lags, out->lags, out->estimator) != GR_OK) {
        gr_error_set(err, GR_ERR_NOMEM, -1, -1, NAN, NAN, "no memory for the TAMSD plan");
        return GR_ERR_NOMEM;
    }
    const run_shared rs = {cfg, &sp, out, &plan, n, step_from, step_to, n_steps,
                           first_sample_from(out, step_from)};
    double *sums = calloc((size_t)(nb * row) + 1, sizeof(double));
    worker *ws = calloc((size_t)nt, sizeof(worker));
    pthread_t *tid = calloc((size_t)nt, sizeof(pthread_t));
    int *started = calloc((size_t)nt, sizeof(int));
    double *rings = calloc((size_t)((nt - 1) * ring_n) + 1, sizeof(double));
    int64_t *slow = calloc((size_t)(nt * plan.n_slow) + 1, sizeof(int64_t));
    int status = GR_OK;
    if (!sums || !ws || !tid || !started || !rings || !slow) {
        gr_error_set(err, GR_ERR_NOMEM, -1, -1, NAN, NAN, "no memory for the SDE threads");
        status = GR_ERR_NOMEM;
        goto done;
    }
    if (out->carry) memcpy(sums, out->carry, (size_t)row * sizeof(double));
    for (int64_t t = 0; t < nt; t++) {
        /* thread t takes blocks [b_first + nb t / nt, b_first + nb (t+1) / nt) */
        const int64_t lo = (b_first + nb * t / nt) * GR_SDE_BLOCK;
        const int64_t hi = (b_first + nb * (t + 1) / nt) * GR_SDE_BLOCK;
        ws[t] = (worker){&rs, lo > first ? lo : first, hi < first + count ? hi : first + count,
                         first, x, v, sums,
                         t == 0 ? out->ring : rings + (t - 1) * ring_n, slow + t * plan.n_slow,
                         GR_OK, -1};
    }
    /* threads 1.. run beside this one; one that cannot be started runs here afterwards
     * (the same numbers, later) */
    for (int64_t t = 1; t < nt; t++) started[t] = pthread_create(&tid[t], NULL, work, &ws[t]) == 0;
    work(&ws[0]);
    for (int64_t t = 1; t < nt; t++) {
        if (started[t]) pthread_join(tid[t], NULL);
        else work(&ws[t]);
    }
    for (int64_t t = 0; t < nt; t++)
        if (ws[t].status != GR_OK) { /* the first failure in particle order */
            status = ws[t].status;
            gr_error_set(err, status, ws[t].bad, -1, NAN, NAN, "in the SDE state");
            break;
        }
    if (status == GR_OK) {
        /* Blocks complete in this call go to x2, v2 in order; the last, if a later call
         * continues it (more of its particles, or more of this particle's steps), stays
         * in the carry.  Without a carry the call ends the sums. */
        const int64_t end = first + count;
        const int done = step_to == n_steps;
        for (int64_t b = 0; b < nb; b++) {
            const double *s = sums + b * row;
            int64_t block_end = (b_first + b + 1) * GR_SDE_BLOCK;
            if (block_end > n) block_end = n;
            if (out->carry && (!done || end < block_end)) {
                memcpy(out->carry, s, (size_t)row * sizeof(double));
                break; /* only the last block can be open */
            }
            for (int64_t k = 0; k < T * d; k++) {
                out->x2[k] += s[k];
                out->v2[k] += s[T * d + k];
            }
            if (out->carry) memset(out->carry, 0, (size_t)row * sizeof(double));
        }
    }
done:
    free(sums), free(ws), free(tid), free(started), free(rings), free(slow);
    gr_tamsd_plan_free(&plan);
    return status;
}
