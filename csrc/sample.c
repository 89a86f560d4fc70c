/* sample.c -- reading the state out: samples during a run, the state and the counters
 * between runs. */
#include <math.h>

#include "engine.h"

void gr_write_sample(const gr_edmd *s, gr_edmd_samples *smp, double ts)
{
    const int dim = s->dim, dyn = dynamics_of(s);
    const int64_t k = smp->next;
    const size_t base = (size_t)k * s->n * dim;
    double kin = 0.0, mom[3] = {0.0, 0.0, 0.0};
    for (int32_t i = 0; i < s->n; i++) {
        const double *p = rec(s, dim, i);
        const double dt = ts - TIME(p, dim), m = s->mass[i];
        const size_t out = base + (size_t)s->order.id_of[i] * dim;
        for (int a = 0; a < dim; a++) {
            const double g = s->cfg.gravity[a];
            double v = fl_vel_at(dyn, VEL(p, dim)[a], g, dt);
            if (smp->pos)
                smp->pos[out + a] = bd_unwrap(fl_at(dyn, p[a], VEL(p, dim)[a], g, dt),
                                              s->image[(size_t)i * dim + a], s->L[a]);
            if (smp->vel) smp->vel[out + a] = v;
            mom[a] += m * v;
            kin += 0.5 * m * v * v;
        }
    }
    if (smp->kinetic) smp->kinetic[k] = kin;
    if (smp->momentum)
        for (int a = 0; a < dim; a++) smp->momentum[(size_t)k * dim + a] = mom[a];
    if (smp->pair) smp->pair[k] = s->pair;
    if (smp->wall) smp->wall[k] = s->wall;
    if (smp->virial) smp->virial[k] = s->virial;
    if (smp->wall_impulse) smp->wall_impulse[k] = s->wall_impulse;
    smp->next = k + 1;
}

void gr_edmd_state(const gr_edmd *s, double *pos, double *vel, int64_t *image)
{
    const int d = s->dim, dyn = dynamics_of(s);
    for (int32_t i = 0; i < s->n; i++) {
        const double *p = rec(s, d, i);
        double dt = s->t - TIME(p, d);
        for (int a = 0; a < d; a++) {
            double x = fl_at(dyn, p[a], VEL(p, d)[a], s->cfg.gravity[a], dt);
            int64_t img = s->image[(size_t)i * d + a];
            size_t out = (size_t)s->order.id_of[i] * d + a;
            /* a crossing due exactly now may not have been processed yet */
            if (s->cfg.periodic) bd_reenter(&x, s->cfg.lo[a], s->cfg.hi[a], s->L[a], &img);
            if (pos) pos[out] = x;
            if (vel) vel[out] = fl_vel_at(dyn, VEL(p, d)[a], s->cfg.gravity[a], dt);
            if (image) image[out] = img;
        }
    }
}

void gr_edmd_get_counters(const gr_edmd *s, gr_edmd_counters *c)
{
    c->t = s->t;
    c->events = s->events;
    c->pair = s->pair;
    c->wall = s->wall;
    c->crossings = s->crossings;
    c->shell_exits = s->shell_exits;
    c->invalid = s->invalid;
    c->elastic_tc = s->elastic_tc;
    c->law_clamped = s->law_clamped;
    c->virial = s->virial;
    c->wall_impulse = s->wall_impulse;
    c->kinetic_time = s->kinetic_time;
    c->kinetic = kinetic_total(s, dynamics_of(s), s->dim, NULL);
    for (int a = 0; a < 3; a++) c->ncell[a] = s->cells.nc[a];
    c->shell = s->nl.shell > 0.0 ? s->cfg.shell : 0.0;
}
