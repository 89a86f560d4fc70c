/* sde.c -- Euler-Maruyama and exact integration of the underdamped Langevin equation and
 * of UDSBM (see sde.h), with the ensemble MSD and the time-averaged MSD accumulated on
 * the fly.
 *
 * Each particle is independent, so the loop runs over particles outside and steps
 * inside: a particle's state stays in registers for the whole run, and the TAMSD needs
 * only the ring of one particle's recent positions at a time (O(lags) memory, not
 * O(N x steps)).  Invariant: a particle's random numbers depend only on (key, step,
 * particle), never on the order of work. */
#include <math.h>
#include <string.h>

#include "rng.h"
#include "sde.h"

#define GR_TAMSD_WINDOWS_PER_LAG 16

int64_t gr_sde_lag_stride(int64_t lag)
{
    int64_t s = lag / GR_TAMSD_WINDOWS_PER_LAG;
    return s < 1 ? 1 : s;
}

int64_t gr_sde_ring_len(int64_t lag)
{
    /* ceil(lag / s) + 1, written so that no intermediate exceeds lag */
    return (lag - 1) / gr_sde_lag_stride(lag) + 2;
}

int64_t gr_sde_ring_size(int dim, int64_t n_lags, const int64_t *lags)
{
    int64_t total = 0;
    for (int64_t l = 0; l < n_lags; l++) {
        const int64_t need = gr_sde_ring_len(lags[l]) * dim; /* <= 32 x 3 */
        if (total > INT64_MAX - need) return -1;
        total += need;
    }
    return total;
}

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
} step_params;

/* Steps from+1 .. to of particle i (the step numbered k goes from t = (k-1) dt to k dt and
 * draws the randoms of (key, k-1, i)).  Always inlined with a constant d, so that each
 * dimension gets its own unrolled loop. */
#if defined(__GNUC__) || defined(__clang__)
#define GR_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define GR_ALWAYS_INLINE inline
#endif

static GR_ALWAYS_INLINE void run_steps(
    const int d, const step_params *p, int64_t i, int64_t from, int64_t to, double *xi, double *vi)
{
    const double dt = p->dt;
    for (int64_t step = from + 1; step <= to; step++) {
        gr_stream rs = gr_stream_at(p->key, (uint64_t)(step - 1), (uint64_t)i);
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
                double z = gr_normal(&rs);
                xi[a] += vi[a] * dt;
                vi[a] = a_coef * vi[a] + b * z;
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
            for (int a = 0; a < d; a++) {
                double z1 = gr_normal(&rs), z2 = gr_normal(&rs);
                xi[a] += vi[a] * e.drift + e.kx * z1 + e.sx * z2;
                vi[a] = e.c * vi[a] + e.sv * z1;
            }
        }
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

int gr_sde_run(const gr_sde_config *cfg, int64_t n, int64_t first, int64_t count,
               int64_t step_from, int64_t step_to, int64_t n_steps, double *x, double *v,
               gr_sde_output *out, gr_error *err)
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
        (!whole && count > 1)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, NAN, "invalid SDE parameters");
        return GR_ERR_VALUE;
    }
    if (cfg->scheme == GR_SDE_EM && g0 * dt >= 2.0) {
        gr_error_set(err, GR_ERR_UNSTABLE, -1, -1, NAN, g0 * dt,
                     "Euler-Maruyama diverges for gamma0*dt >= 2; take a smaller dt or the "
                     "exact scheme (scheme='exact'), stable at any step");
        return GR_ERR_UNSTABLE;
    }
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

    const step_params sp = {cfg->key, dt, g0, D0, tau0, b0, expo, udsbm, cfg->scheme == GR_SDE_EM,
                            ex0, table, step_from, em_table};
    /* where the segment starts among the samples */
    const int64_t ks0 = first_sample_from(out, step_from);
    for (int64_t local = 0; local < count; local++) {
        const int64_t i = first + local;
        double xi[3] = {0, 0, 0}, vi[3] = {0, 0, 0};
        for (int a = 0; a < d; a++) {
            xi[a] = x[local * d + a];
            vi[a] = v[local * d + a];
        }
        int64_t ks = ks0;
        /* Per lag: next window end, next store, their ring slots (no divisions per step).
         * The k-th store (k = 0, 1, ...) is at step k stride into slot k mod len, the k-th
         * window ends at lag + k stride and reads that slot: so the counters at step_from
         * follow from step_from alone, and only the ring carries over between segments. */
        int64_t *next_end = out->lag_work, *next_store = next_end + out->n_lags;
        int64_t *slot_end = next_store + out->n_lags, *slot_store = slot_end + out->n_lags;
        for (int64_t l = 0; l < out->n_lags; l++) {
            const int64_t lag = out->lags[l], stride = out->lag_stride[l], len = out->lag_len[l];
            int64_t k = step_from / stride + (step_from % stride != 0);
            next_store[l] = k * stride;
            slot_store[l] = k % len;
            k = step_from <= lag ? 0 : (step_from - lag - 1) / stride + 1;
            next_end[l] = lag + k * stride;
            slot_end[l] = k % len;
        }
        /* Bookkeeping (samples, TAMSD windows) happens at few steps; between them the
         * particle is stepped in a tight loop.  Step 0, the start, is a sample and a
         * window start for every lag. */
        for (int64_t step = step_from;;) {
            if (step == step_to && step_to < n_steps) break; /* booked by the next segment */
            while (ks < out->n_samples && out->sample_steps[ks] == step) {
                for (int a = 0; a < d; a++) {
                    out->x2[ks * d + a] += xi[a] * xi[a];
                    out->v2[ks * d + a] += vi[a] * vi[a];
                    if (out->positions) out->positions[(ks * n + i) * d + a] = xi[a];
                }
                ks++;
            }
            int64_t next = step_to; /* the next step that needs bookkeeping */
            if (ks < out->n_samples && out->sample_steps[ks] < next) next = out->sample_steps[ks];
            double *r = out->ring;
            for (int64_t l = 0; l < out->n_lags; l++) {
                const int64_t stride = out->lag_stride[l], len = out->lag_len[l];
                if (step == next_end[l]) {
                    const double *old = r + slot_end[l] * d;
                    double sum = 0.0;
                    for (int a = 0; a < d; a++) sum += (xi[a] - old[a]) * (xi[a] - old[a]);
                    out->tamsd[i * out->n_lags + l] += sum;
                    next_end[l] += stride;
                    if (++slot_end[l] == len) slot_end[l] = 0;
                }
                if (step == next_store[l]) {
                    memcpy(r + slot_store[l] * d, xi, (size_t)d * sizeof(double));
                    next_store[l] += stride;
                    if (++slot_store[l] == len) slot_store[l] = 0;
                }
                if (next_end[l] < next) next = next_end[l];
                if (next_store[l] < next) next = next_store[l];
                r += len * d;
            }
            if (step == n_steps) break;
            /* steps step+1 .. next, each with its own dimension so that the axis loops
             * unroll */
            switch (d) {
            case 1: run_steps(1, &sp, i, step, next, xi, vi); break;
            case 2: run_steps(2, &sp, i, step, next, xi, vi); break;
            default: run_steps(3, &sp, i, step, next, xi, vi); break;
            }
            step = next;
        }
        for (int a = 0; a < d; a++) {
            if (!isfinite(xi[a]) || !isfinite(vi[a])) {
                gr_error_set(err, GR_ERR_NONFINITE, i, -1, NAN, NAN, "in the SDE state");
                return GR_ERR_NONFINITE;
            }
            x[local * d + a] = xi[a];
            v[local * d + a] = vi[a];
        }
    }
    return GR_OK;
}
