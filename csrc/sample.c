/* sample.c -- reading the state out: samples during a run, the state and the counters
 * between runs. */
#include <math.h>

#include "engine.h"
#include "stress.h"

/* Sample k's stress tensor parts at ts (stress.h): the cumulative collisional sum and
 * kinetic integral, and the kinetic tensor summed from the velocities at ts. */
static void stress_sample(const gr_edmd *s, gr_edmd_samples *smp, double ts)
{
    const int dim = s->dim, dd = dim * dim, dyn = dynamics_of(s);
    const size_t at = (size_t)smp->next * dd;
    if (s->le) { /* the peculiar tensor, polynomial in flight (stress.h) */
        double k[9], kt[9];
        stress_le_at(dim, s->cfg.shear_rate, s->st_kin, ts - s->stress_t, k, kt);
        for (int c = 0; c < dd; c++) {
            if (smp->stress_collisional) smp->stress_collisional[at + c] = s->st_coll[c];
            if (smp->kinetic_time_tensor) smp->kinetic_time_tensor[at + c] = s->st_kin_time[c] + kt[c];
        }
        if (!smp->kinetic_tensor) return;
        double ks[9] = {0.0}; /* summed from the particles, as below */
        for (int32_t i = 0; i < s->n; i++) {
            double V[3];
            stress_le_peculiar(s, dim, rec(s, dim, i), ts, V);
            for (int a = 0; a < dim; a++)
                for (int b = 0; b < dim; b++) ks[a * dim + b] += s->mass[i] * V[a] * V[b];
        }
        for (int c = 0; c < dd; c++) smp->kinetic_tensor[at + c] = ks[c];
        return;
    }
    double k_now[9], kt[9]; /* under gravity K changes in flight (stress.h) */
    stress_kinetic_at(s, dim, ts, k_now, kt);
    for (int c = 0; c < dd; c++) {
        if (smp->stress_collisional) smp->stress_collisional[at + c] = s->st_coll[c];
        if (smp->kinetic_time_tensor) smp->kinetic_time_tensor[at + c] = s->st_kin_time[c] + kt[c];
    }
    if (!smp->kinetic_tensor) return;
    double k[9] = {0.0};
    for (int32_t i = 0; i < s->n; i++) {
        const double *p = rec(s, dim, i), m = s->mass[i], dt = ts - TIME(p, dim);
        double v[3];
        for (int a = 0; a < dim; a++) v[a] = fl_vel_at(dyn, VEL(p, dim)[a], s->cfg.gravity[a], dt);
        for (int a = 0; a < dim; a++)
            for (int b = 0; b < dim; b++) k[a * dim + b] += m * v[a] * v[b];
    }
    for (int c = 0; c < dd; c++) smp->kinetic_tensor[at + c] = k[c];
}

/* A sheared box's lists let a particle stray a shell beyond a y face before its shell
 * exit brings it back (edmd.c le_list_reenter): its record's v_x is that of the box it
 * left, and the box's own is v_x -+ u (as state_sheared reports it).  0 in the box. */
static double le_frame_velocity(const gr_edmd *s, int dyn, const double *p, double dt)
{
    const int dim = s->dim;
    const double y = fl_at(dyn, p[1], VEL(p, dim)[1], s->cfg.gravity[1], dt);
    return y >= s->cfg.hi[1] ? -s->le_u : y < s->cfg.lo[1] ? s->le_u : 0.0;
}

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
            if (s->le && a == 0) v += le_frame_velocity(s, dyn, p, dt);
            if (smp->pos)
                smp->pos[out + a] = bd_unwrap(fl_at(dyn, p[a], VEL(p, dim)[a], g, dt),
                                              s->image[(size_t)i * dim + a], s->L[a]);
            if (smp->pos && a == 0 && s->le) /* boundary.h: + img_y D(t) */
                smp->pos[out] += (double)s->image[(size_t)i * dim + 1] *
                                 bd_le_total(s->cfg.shear_offset, s->le_u, ts);
            if (smp->vel) smp->vel[out + a] = v;
            mom[a] += m * v;
            kin += 0.5 * m * v * v;
        }
        if (smp->spin && s->spin) /* spins do not change in flight */
            for (int a = 0; a < GR_SPIN_DIM(dim); a++)
                smp->spin[((size_t)k * s->n + (size_t)s->order.id_of[i]) * GR_SPIN_DIM(dim) + a] =
                    s->spin[(size_t)i * GR_SPIN_DIM(dim) + a];
    }
    if (smp->kinetic) smp->kinetic[k] = kin;
    if (smp->momentum)
        for (int a = 0; a < dim; a++) smp->momentum[(size_t)k * dim + a] = mom[a];
    if (smp->pair) smp->pair[k] = s->pair;
    if (smp->wall) smp->wall[k] = s->wall;
    if (smp->virial) smp->virial[k] = s->virial;
    if (smp->wall_impulse) smp->wall_impulse[k] = s->wall_impulse;
    if (smp->wall_work) smp->wall_work[k] = s->wall_work;
    if (smp->collision_loss) smp->collision_loss[k] = s->collision_loss;
    if (s->cfg.stress) stress_sample(s, smp, ts);
    smp->next = k + 1;
}

/* gr_edmd_state of particle i in a sheared box (boundary.h): a particle due to cross a y
 * face now re-enters with its x and v_x moved as edmd.c do_face_sheared moves them. */
static void state_sheared(const gr_edmd *s, int32_t i, double *pos, double *vel, int64_t *image)
{
    const int d = s->dim, dyn = dynamics_of(s);
    const double *p = rec(s, d, i);
    const double dt = s->t - TIME(p, d);
    double x[3], v[3];
    int64_t img[3];
    for (int a = 0; a < d; a++) {
        x[a] = fl_at(dyn, p[a], VEL(p, d)[a], s->cfg.gravity[a], dt);
        v[a] = fl_vel_at(dyn, VEL(p, d)[a], s->cfg.gravity[a], dt);
        img[a] = s->image[(size_t)i * d + a];
    }
    const int64_t img_y = img[1];
    /* x in the box first (lists let it stray a shell beyond), so that the shift by delta
     * leaves it at most one box length out */
    bd_reenter(&x[0], s->cfg.lo[0], s->cfg.hi[0], s->L[0], &img[0]);
    if (bd_reenter(&x[1], s->cfg.lo[1], s->cfg.hi[1], s->L[1], &img[1])) {
        const double sign = img[1] > img_y ? -1.0 : 1.0;
        const double D = bd_le_total(s->cfg.shear_offset, s->le_u, s->t);
        const double delta = bd_le_offset(s->cfg.shear_offset, s->le_u, s->t, s->L[0]);
        x[0] += sign * delta;
        v[0] += sign * s->le_u;
        img[0] += (int64_t)llround(sign * (D - delta) / s->L[0]);
    }
    for (int a = 0; a < d; a++) {
        if (a != 1) bd_reenter(&x[a], s->cfg.lo[a], s->cfg.hi[a], s->L[a], &img[a]);
        const size_t out = (size_t)s->order.id_of[i] * d + a;
        if (pos) pos[out] = x[a];
        if (vel) vel[out] = v[a];
        if (image) image[out] = img[a];
    }
}

void gr_edmd_state(const gr_edmd *s, double *pos, double *vel, int64_t *image)
{
    const int d = s->dim, dyn = dynamics_of(s);
    for (int32_t i = 0; i < s->n; i++) {
        if (s->le) {
            state_sheared(s, i, pos, vel, image);
            continue;
        }
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

int gr_edmd_has_spin(const gr_edmd *s) { return s->spin != NULL; }

void gr_edmd_spin(const gr_edmd *s, double *spin)
{
    const int w = GR_SPIN_DIM(s->dim);
    if (!s->spin) return;
    for (int32_t i = 0; i < s->n; i++)
        for (int a = 0; a < w; a++)
            spin[(size_t)s->order.id_of[i] * w + a] = s->spin[(size_t)i * w + a];
}

/* The counters of a sheared box with lists: a particle strayed beyond a y face (its
 * record in the frame of the box it left, le_frame_velocity) counts with the box's
 * velocity, and the work its re-entry will book (edmd.c le_face_moves) is counted now,
 * so that the kinetic energy is the box velocities' total and still rises by the work. */
static void le_counters_in_box(const gr_edmd *s, double *kinetic, double *work)
{
    const int dim = s->dim, dyn = dynamics_of(s);
    for (int32_t i = 0; i < s->n; i++) {
        const double *p = rec(s, dim, i), dt = s->t - TIME(p, dim);
        const double du = le_frame_velocity(s, dyn, p, dt);
        if (du == 0.0) continue;
        const double v0 = fl_vel_at(dyn, VEL(p, dim)[0], s->cfg.gravity[0], dt), v1 = v0 + du;
        *kinetic += 0.5 * s->mass[i] * (v1 * v1 - v0 * v0);
        *work += du * s->mass[i] * 0.5 * (v0 + v1); /* as le_face_moves: sign u = du */
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
    c->wall_work = s->wall_work;
    c->collision_loss = s->collision_loss;
    c->kinetic_time = s->kinetic_time;
    c->shear_work = s->shear_work;
    c->kinetic = kinetic_total(s, dynamics_of(s), s->dim, NULL);
    for (int a = 0; a < 3; a++) c->ncell[a] = s->cells.nc[a];
    for (int k = 0; k < 9; k++) { /* zeros without cfg.stress (calloc) */
        c->stress_collisional[k] = s->st_coll[k];
        c->kinetic_time_tensor[k] = s->st_kin_time[k];
        c->kinetic_tensor[k] = s->st_kin[k];
    }
    if (s->cfg.stress) { /* K and its integral brought from stress_t to t (stress.h) */
        double k[9], kt[9];
        stress_kinetic_at(s, s->dim, s->t, k, kt);
        for (int a = 0; a < s->dim * s->dim; a++) {
            c->kinetic_time_tensor[a] += kt[a];
            c->kinetic_tensor[a] = k[a];
        }
    }
    if (s->le && s->nl.shell > 0.0) le_counters_in_box(s, &c->kinetic, &c->shear_work);
    c->shell = s->nl.shell > 0.0 ? s->cfg.shell : 0.0;
    c->kicks = s->kicks;
    c->drive_energy = s->drive_energy;
}
