/* drive.c -- the random driving force: kicks to random pairs at the times of a Poisson
 * process, between runs of the plain event loop (drive.h says what and why). */
#include <math.h>

#include "drive.h"
#include "engine.h"
#include "rng.h"
#include "stress.h"

static uint64_t key_of(const gr_edmd_config *cfg) { return (uint64_t)cfg->drive_seed; }

double gr_drive_wait(const gr_edmd_config *cfg, int64_t k)
{
    gr_stream st = gr_stream_at(key_of(cfg), (uint64_t)k, 1);
    return -log(gr_uniform(&st)) / (0.5 * cfg->drive_rate * (double)cfg->n);
}

int gr_drive_check(const gr_edmd_config *cfg, gr_error *err)
{
    const double kind = cfg->drive_kind;
    if (kind == GR_DRIVE_NONE) return GR_OK;
    if (kind != GR_DRIVE_WHITE_NOISE && kind != GR_DRIVE_THERMOSTAT) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, kind,
                     "drive_kind must be 0 (none), 1 (white noise) or 2 (thermostat)");
        return GR_ERR_VALUE;
    }
    if (cfg->n < 2) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, (double)cfg->n,
                     "random driving kicks pairs: it needs at least 2 particles");
        return GR_ERR_VALUE;
    }
    /* the total rate and its waiting times must be finite and nonzero in float64 */
    const double total = 0.5 * cfg->drive_rate * (double)cfg->n;
    if (!(cfg->drive_rate > 0.0 && isfinite(total) && total >= 1e-140 && total <= 1e140)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->drive_rate,
                     "drive_rate must be positive and finite, with rate * N / 2 in "
                     "1e-140 .. 1e140");
        return GR_ERR_VALUE;
    }
    if (!(cfg->drive_strength > 0.0 && cfg->drive_strength <= 1e140 &&
          cfg->drive_strength / cfg->drive_rate <= 1e140)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->drive_strength,
                     "drive_strength must be positive and finite (at most 1e140, and "
                     "strength / rate too)");
        return GR_ERR_VALUE;
    }
    if (!(cfg->drive_seed >= 0.0 && cfg->drive_seed < GR_DRIVE_SEED_LIMIT &&
          cfg->drive_seed == floor(cfg->drive_seed))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->drive_seed,
                     "drive_seed must be an integer in [0, 2^53)");
        return GR_ERR_VALUE;
    }
    return GR_OK;
}

/* Kick number s->kicks, at s->drive_next (the system's clock). */
static int kick(gr_edmd *s, gr_error *err)
{
    const int d = s->dim, dyn = dynamics_of(s);
    const double t = s->drive_next;
    const int32_t n = s->n;
    gr_stream st = gr_stream_at(key_of(&s->cfg), (uint64_t)s->kicks, 0);
    int32_t i = (int32_t)(gr_uniform(&st) * (double)n);
    int32_t j = (int32_t)(gr_uniform(&st) * (double)(n - 1));
    if (i > n - 1) i = n - 1; /* (a uniform below 1 cannot round to n; kept safe) */
    if (j > n - 2) j = n - 2;
    if (j >= i) j++;
    double *p = rec(s, d, i), *q = rec(s, d, j);
    move(s, dyn, d, p, t);
    move(s, dyn, d, q, t);
    double *vi = VEL(p, d), *vj = VEL(q, d);
    const double mi = s->mass[i], mj = s->mass[j];
    const double before = fl_kinetic(dyn, d, mi, vi) + fl_kinetic(dyn, d, mj, vj);
    const double M = mi + mj, mu = mi * mj / M;
    /* In a sheared box the mean flow at each particle, shear_rate (y - y_c) along x: the
     * thermostat acts on the velocities less it (a pair far apart in y must not lose its
     * share of the flow) and the stress tensor keeps the peculiar ones (stress.h). */
    const double yc = 0.5 * (s->cfg.lo[1] + s->cfg.hi[1]);
    const double ui = s->le ? s->cfg.shear_rate * (p[1] - yc) : 0.0;
    const double uj = s->le ? s->cfg.shear_rate * (q[1] - yc) : 0.0;
    double vb[6]; /* the (peculiar) velocities before, for the stress tensor's kinetic part */
    for (int a = 0; a < d; a++) vb[a] = vi[a], vb[3 + a] = vj[a];
    vb[0] -= ui;
    vb[3] -= uj;
    if (s->cfg.drive_kind == GR_DRIVE_WHITE_NOISE) {
        const double amp = 2.0 * mu * sqrt(s->cfg.drive_strength / s->cfg.drive_rate);
        for (int a = 0; a < d; a++) {
            const double dp = amp * gr_normal(&st);
            vi[a] += dp / mi;
            vj[a] -= dp / mj;
        }
    } else {
        const double sd = sqrt(s->cfg.drive_strength / mu);
        for (int a = 0; a < d; a++) {
            const double fi = a == 0 ? ui : 0.0, fj = a == 0 ? uj : 0.0;
            const double v = (mi * (vi[a] - fi) + mj * (vj[a] - fj)) / M, g = sd * gr_normal(&st);
            vi[a] = v + (mj / M) * g + fi;
            vj[a] = v - (mi / M) * g + fj;
        }
    }
    for (int a = 0; a < d; a++) {
        if (!isfinite(vi[a]) || !isfinite(vj[a]) || !(fabs(vi[a]) <= 1e140) ||
            !(fabs(vj[a]) <= 1e140)) {
            gr_error_set(err, GR_ERR_NONFINITE, uid(s, i), uid(s, j), t,
                         isfinite(vi[a]) ? vj[a] : vi[a],
                         "a velocity after a random kick (beyond 1e140: the driving heats the "
                         "gas past what float64 can time)");
            return GR_ERR_NONFINITE;
        }
    }
    const double gain = fl_kinetic(dyn, d, mi, vi) + fl_kinetic(dyn, d, mj, vj) - before;
    s->kinetic += gain;
    s->drive_energy += gain;
    if (s->cfg.stress) { /* a kick is an outside force: only the kinetic tensor changes */
        double V[6] = {0.0};
        for (int a = 0; a < d; a++) V[a] = vi[a], V[3 + a] = vj[a];
        V[0] -= ui;
        V[3] -= uj;
        stress_sync(s, d, t);
        stress_kick(s, d, mi, vb, V);
        stress_kick(s, d, mj, vb + 3, V + 3);
    }
    /* predictions that others made with i's or j's old velocities become stale */
    s->sched[i].count++;
    s->sched[j].count++;
    s->kicks++;
    s->events++;
    s->drive_next = t + gr_drive_wait(&s->cfg, s->kicks);
    gr_predict_one(s, i);
    gr_predict_one(s, j);
    return GR_OK;
}

int gr_drive_advance(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err)
{
    gr_edmd_stop until = *stop;
    for (;;) {
        /* the plain loop up to the next kick: it takes events at times <= t_stop and
         * brings the clock to t_stop (samples at the kick's time see the state before it) */
        until.t_stop = fmin(stop->t_stop, s->drive_next);
        const int64_t e0 = s->events;
        int status = gr_edmd_advance_plain(s, &until, smp, err);
        until.max_events -= s->events - e0;
        if (status != GR_STOP_TIME || !(s->drive_next <= stop->t_stop)) return status;
        if (until.max_events <= 0) return GR_STOP_BUDGET; /* the kick is the next event */
        status = kick(s, err);
        if (status != GR_OK) return status;
        until.max_events--;
        if (!(s->drive_next >= s->t && s->drive_next < INFINITY)) { /* (never: the check) */
            gr_error_set(err, GR_ERR_NONFINITE, -1, -1, s->t, s->drive_next,
                         "the next random kick's time");
            return GR_ERR_NONFINITE;
        }
    }
}
