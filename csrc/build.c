/* build.c -- building a system from arrays (gr_edmd_new) and freeing it. */
#define _DEFAULT_SOURCE         /* madvise (hugemem.h) */
#define _POSIX_C_SOURCE 200112L /* posix_memalign */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "drive.h"
#include "engine.h"
#include "hugemem.h"
#include "le_cells.h"
#include "stress.h"

void gr_edmd_free(gr_edmd *s)
{
    if (!s) return;
    free(s->P);
    free(s->mass);
    free(s->spin);
    free(s->image);
    free(s->sched);
    free(s->order.id_of);
    free(s->order.scratch);
    free(s->big.is_big);
    free((void *)s->cfg.law.speeds); /* the engine's own copies (copy_law) */
    free((void *)s->cfg.law.values);
    free((void *)s->cfg.wall_law.speeds);
    free((void *)s->cfg.wall_law.values);
    gr_cq_free(&s->queue);
    gr_cells_free(&s->cells);
    gr_nlist_free(&s->nl);
    free(s);
}

/* Bytes of the renumbering's scratch per particle: room for a record or a scheduling
 * state, whichever is larger. */
static size_t scratch_per_particle(int dim)
{
    const size_t record = (size_t)GR_STRIDE(dim) * sizeof(double);
    return record > sizeof(gr_sched) ? record : sizeof(gr_sched);
}

/* Replace a table law's pointers (the caller's arrays) by copies the engine owns; on
 * failure the pointers are NULL (gr_edmd_free then frees what was copied). */
static int copy_law(gr_law *law)
{
    const double *x = law->speeds, *y = law->values;
    law->speeds = law->values = NULL;
    if (law->kind != GR_LAW_TABLE) return GR_OK;
    size_t bytes = (size_t)law->count * sizeof(double);
    double *cx = malloc(bytes), *cy = malloc(bytes);
    if (!cx || !cy) {
        free(cx);
        free(cy);
        return GR_ERR_NOMEM;
    }
    memcpy(cx, x, bytes);
    memcpy(cy, y, bytes);
    law->speeds = cx;
    law->values = cy;
    return GR_OK;
}

size_t gr_edmd_bytes_per_particle(int dim, int lists)
{
    size_t bytes = (size_t)GR_STRIDE(dim) * sizeof(double) /* record */
                   + sizeof(double)                       /* mass */
                   + (size_t)dim * sizeof(int64_t)        /* image */
                   + sizeof(gr_sched)
                   + sizeof(int32_t)                      /* cell link */
                   + sizeof(int32_t) + sizeof(uint8_t)    /* id_of, is_big */
                   + scratch_per_particle(dim)
                   + sizeof(gr_cq_item) + sizeof(int32_t) /* queue entry, a bucket's share */
                   + 8 * sizeof(int32_t) + 1;             /* cell heads and bits: at most 8 cells each */
    if (lists)
        bytes += (size_t)(dim + 1) * sizeof(double)       /* centre */
                 + 2 * (size_t)(dim == 3 ? 32 : 16) * sizeof(int32_t) /* a row, its copy
                                                                      * while renumbering */
                 + sizeof(int32_t) + sizeof(uint8_t)      /* near, mark */
                 + 3 * sizeof(double) + sizeof(int8_t)    /* a sheared box's build time,
                                                           * expiry, lap */
                 + 8 * GR_LE_BLOCK * sizeof(int32_t);     /* its cells' blocks: at most 8
                                                           * cells each */
    return bytes;
}

int gr_edmd_new(gr_edmd **out, const gr_edmd_config *cfg, const double *pos,
                const double *vel, const double *radius, const double *mass, gr_error *err)
{
    *out = NULL;
    int status = gr_validate_config(cfg, pos, vel, radius, mass, err);
    if (status != GR_OK) return status;
    const int d = cfg->dim;
    const int32_t n = (int32_t)cfg->n;
    double sigma_max = 0.0, sigma_min = INFINITY;
    for (int32_t i = 0; i < n; i++) {
        if (2.0 * radius[i] > sigma_max) sigma_max = 2.0 * radius[i];
        if (2.0 * radius[i] < sigma_min) sigma_min = 2.0 * radius[i];
    }

    gr_edmd *s = calloc(1, sizeof *s);
    if (!s) return GR_ERR_NOMEM;
    s->cfg = *cfg;
    status = copy_law(&s->cfg.law);
    int wall_status = copy_law(&s->cfg.wall_law); /* always: it drops the caller's pointers */
    if (status == GR_OK) status = wall_status;
    s->dim = d;
    s->n = n;
    s->cfg.spin = NULL; /* the caller's array: copied into s->spin below */
    if (cfg->spin) {
        const size_t bytes = (size_t)n * GR_SPIN_DIM(d) * sizeof *s->spin;
        s->spin = malloc(bytes);
        if (s->spin) memcpy(s->spin, cfg->spin, bytes);
        else status = GR_ERR_NOMEM;
    }
    for (int a = 0; a < 3; a++) s->L[a] = a < d ? cfg->hi[a] - cfg->lo[a] : 1.0;
    /* Lees-Edwards (boundary.h): every particle in the cells or the lists (the big
     * particles' image tables are fixed, the sliding images are not); the lists move
     * with the mean flow (nlist.h) */
    s->le = cfg->periodic && cfg->shear_rate != 0.0;
    const int sheared = s->le;
    s->le_u = cfg->shear_rate * s->L[1];
    size_t bytes = ((size_t)n * GR_STRIDE(d) * sizeof(double) + 63) / 64 * 64;
    s->P = gr_big_alloc(bytes); /* records on cache-line boundaries: a record is one line */
    if (s->P) memset(s->P, 0, bytes); /* the 2D records' padding too (checkpoints hold it) */
    s->mass = gr_big_alloc((size_t)n * sizeof *s->mass);
    s->image = calloc((size_t)n * d, sizeof *s->image);
    s->sched = gr_big_alloc((size_t)n * sizeof *s->sched);
    s->order.id_of = malloc((size_t)n * sizeof *s->order.id_of);
    s->big.is_big = calloc((size_t)n, sizeof *s->big.is_big);
    if (n >= GR_RENUMBER_MIN_N) s->order.scratch = malloc((size_t)n * scratch_per_particle(d));
    if (!s->P || !s->mass || !s->image || !s->sched || !s->order.id_of || !s->big.is_big ||
        (n >= GR_RENUMBER_MIN_N && !s->order.scratch))
        status = GR_ERR_NOMEM;
    if (status == GR_OK) status = gr_cq_init(&s->queue, n);
    /* List mode, unless the box is too small for the shell: every pair within reach
     * must be less than half a box apart for the nearest image to be the one that
     * collides (list centres within sigma + 2 delta, positions within delta of them). */
    double shell = cfg->shell * sigma_max;
    for (int a = 0; a < d; a++)
        if (cfg->periodic && !(s->L[a] > 2.0 * (sigma_max + 4.0 * shell))) shell = 0.0;
    if (n >= GR_NL_MAX_N) shell = 0.0;
    /* under shear a list's life is bounded by a strain that the box must leave room for */
    if (sheared && shell > 0.0 && !(gr_nlist_shear_strain(d, s->L, sigma_max, shell) >= 0.1))
        shell = 0.0;
    if (status == GR_OK && shell > 0.0) {
        status = gr_nlist_init(&s->nl, d, n, shell, s->L);
        if (status == GR_OK && sheared) status = gr_nlist_shear(&s->nl, d, n, cfg->shear_rate, cfg->lo, s->L, sigma_max);
        s->big.r_small = 0.5 * sigma_max; /* no big particles */
    } else if (status == GR_OK) {
        status = gr_big_choose(&s->big, d, n, radius, s->L, sheared ? INFINITY : cfg->big_ratio,
                               cfg->cell_factor);
    }
    if (status == GR_OK)
        status = gr_cells_build(&s->cells, d, n, cfg->lo, s->L, cfg->periodic,
                                (2.0 * s->big.r_small + 2.0 * s->nl.shell) * cfg->cell_factor, err);
    if (status == GR_OK && s->nl.built) { /* a sheared box's lists: its cells' blocks */
        s->nl.blocks = gr_big_alloc((size_t)s->cells.ncells * GR_LE_BLOCK * sizeof(int32_t));
        if (!s->nl.blocks) status = GR_ERR_NOMEM;
        else memset(s->nl.blocks, 0, (size_t)s->cells.ncells * GR_LE_BLOCK * sizeof(int32_t));
    }
    if (status != GR_OK) {
        gr_edmd_free(s);
        return status;
    }
    /* Events are prefetched ahead where the grid is out of cache (cells.h); they need
     * the ids of the next events at hand (calendar.h). */
    s->lookahead = s->nl.shell == 0.0 && s->cells.prefetch_heads;
    s->queue.depth = s->lookahead ? GR_CQ_AHEAD + 1 : 1;
    s->foreseen[0] = s->foreseen[1] = -1;

    double v2m = 0.0, msum = 0.0;
    for (int32_t i = 0; i < n; i++) {
        double *p = rec(s, d, i);
        for (int a = 0; a < d; a++) {
            p[a] = pos[i * d + a];
            p[d + a] = vel[i * d + a];
            v2m += mass[i] * vel[i * d + a] * vel[i * d + a];
            s->momentum[a] += mass[i] * vel[i * d + a];
        }
        TIME(p, d) = 0.0;
        RAD(p, d) = radius[i];
        s->mass[i] = mass[i];
        msum += mass[i];
        s->sched[i] = (gr_sched){.t_coll = INFINITY, .t_cross = INFINITY, .t_last = -INFINITY,
                              .count = 0, .pcount = 0, .partner = -1, .last = -1, .cross = -1,
                              .streak = 0};
        s->order.id_of[i] = i;
        cell_coords(&s->cells, d, p, s->sched[i].c);
        if (!s->big.is_big[i]) cell_insert(&s->cells, i, cell_of(&s->cells, d, s->sched[i].c));
    }
    s->kinetic = 0.5 * v2m;
    if (cfg->stress) stress_resum(s, d); /* the rest of the tensor starts at 0 (calloc) */
    s->mass_total = msum;
    /* The collapse test's notion of "one instant": a billionth of the time a particle
     * of typical speed needs to cross the smallest diameter.  Under gravity the speed
     * is at least that of a fall through it from rest, sqrt(|g| sigma). */
    double vrms = sqrt(v2m / msum), g2 = 0.0;
    for (int a = 0; a < d; a++) g2 += cfg->gravity[a] * cfg->gravity[a];
    vrms = fmax(vrms, sqrt(sqrt(g2) * sigma_min));
    s->eps_t = vrms > 0.0 ? 1e-9 * sigma_min / vrms : 0.0;
    s->t_prev_event = -INFINITY;
    s->drive_next = cfg->drive_kind != GR_DRIVE_NONE ? gr_drive_wait(cfg, 0) : INFINITY;

    status = gr_find_overlap(d, n, s->P, (size_t)GR_STRIDE(d), s->P + 2 * d + 1, (size_t)GR_STRIDE(d),
                             cfg->periodic, s->L, &s->cells, &s->big,
                             sheared ? &cfg->shear_offset : NULL, err);
    if (status == GR_OK) status = gr_predict_all(s, err);
    if (status != GR_OK) {
        gr_edmd_free(s);
        return status;
    }
    *out = s;
    return GR_OK;
}
