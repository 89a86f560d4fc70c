/* validate.c -- is a configuration one the engine can start from?  Arguments in range,
 * finite numbers, everyone in the box, no two particles overlapping.  Used by
 * gr_edmd_new and, without building an engine, by gr_edmd_check. */
#include <math.h>
#include <stdlib.h>

#include "engine.h"

/* A restitution law (restitution.h) the engine can evaluate: kind known, parameters
 * finite and in range, a table increasing in speed with values in [0, 1]. */
static int validate_law(const gr_law *law, gr_error *err)
{
    switch (law->kind) {
    case GR_LAW_CONSTANT:
        return GR_OK;
    case GR_LAW_VISCOELASTIC:
        /* v_max is where the series stops (delta = GR_VISCO_DELTA_MAX); a larger one would
         * let eps = 1 - delta (C1 - C2 delta) climb above 1 past delta = C1 / C2 */
        if (!(law->scale > 0.0 && isfinite(law->scale) && law->v_max > 0.0 &&
              law->v_max <= pow(GR_VISCO_DELTA_MAX / law->scale, 5) * (1.0 + 1e-12))) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, law->scale,
                         "a viscoelastic law needs A kappa^(2/5) > 0 and finite, and "
                         "0 < v_max <= (0.25 / A kappa^(2/5))^5");
            return GR_ERR_VALUE;
        }
        return GR_OK;
    case GR_LAW_TABLE:
        if (!(law->count >= 1 && law->count <= GR_LAW_TABLE_MAX) || !law->speeds || !law->values) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, (double)law->count,
                         "a restitution table needs 1 to " GR_XSTR(GR_LAW_TABLE_MAX) " points");
            return GR_ERR_VALUE;
        }
        for (int64_t k = 0; k < law->count; k++) {
            double v = law->speeds[k], e = law->values[k];
            if (!(v >= 0.0 && isfinite(v)) || (k > 0 && !(v > law->speeds[k - 1]))) {
                gr_error_set(err, GR_ERR_VALUE, k, -1, NAN, v,
                             "a restitution table's speeds must be finite, >= 0 and increasing");
                return GR_ERR_VALUE;
            }
            if (!(e >= 0.0 && e <= 1.0)) {
                gr_error_set(err, GR_ERR_VALUE, k, -1, NAN, e,
                             "a restitution table's values must lie in [0, 1]");
                return GR_ERR_VALUE;
            }
        }
        return GR_OK;
    default:
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, law->kind, "unknown kind of restitution law");
        return GR_ERR_VALUE;
    }
}

int gr_validate_config(const gr_edmd_config *cfg, const double *pos, const double *vel,
                       const double *radius, const double *mass, gr_error *err)
{
    const int d = cfg->dim;
    if (d != 2 && d != 3) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, d, "dim must be 2 or 3");
        return GR_ERR_VALUE;
    }
    if (cfg->n < 1 || cfg->n > INT32_MAX / 2) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, (double)cfg->n,
                     "number of particles must be between 1 and 2^30");
        return GR_ERR_VALUE;
    }
    if (!(cfg->restitution >= 0.0 && cfg->restitution <= 1.0)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->restitution,
                     "restitution must lie in [0, 1]");
        return GR_ERR_VALUE;
    }
    if (!(cfg->wall_restitution > 0.0 && isfinite(cfg->wall_restitution))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->wall_restitution,
                     "wall restitution must be positive and finite");
        return GR_ERR_VALUE;
    }
    int status = validate_law(&cfg->law, err);
    if (status == GR_OK) status = validate_law(&cfg->wall_law, err);
    if (status != GR_OK) return status;
    if (!(cfg->contact_duration >= 0.0 && isfinite(cfg->contact_duration))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->contact_duration,
                     "contact duration must be finite and >= 0");
        return GR_ERR_VALUE;
    }
    if (!(cfg->big_ratio >= 1.0)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->big_ratio, "big_ratio must be >= 1 (inf: none)");
        return GR_ERR_VALUE;
    }
    if (!(cfg->cell_factor >= 1.0 && isfinite(cfg->cell_factor))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->cell_factor,
                     "cell_factor must be >= 1");
        return GR_ERR_VALUE;
    }
    /* a shell thinner than this rebuilds lists every few hundredths of a diameter
     * travelled, and its rounding margin (1e-9 of it) nears that of the coordinates */
    if (!(cfg->shell == 0.0 || (cfg->shell >= 0.01 && isfinite(cfg->shell)))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->shell,
                     "shell must be 0 (cells) or finite and at least 0.01 (largest diameters)");
        return GR_ERR_VALUE;
    }
    /* gravity: finite; in a periodic box only as the free-fall frame asked for; and
     * small enough that g times any length in the box (the quadratics' 4 a d, a speed
     * squared, flight.h) stays within the square of the scale limit (granular/_scales.py):
     * beyond, a flight across a cell cannot be timed in float64 */
    int pulls = 0;
    double box_diag = 0.0;
    for (int a = 0; a < d; a++) box_diag = fmax(box_diag, cfg->hi[a] - cfg->lo[a]);
    for (int a = 0; a < 3; a++) {
        const double g = cfg->gravity[a];
        if (!isfinite(g) || (a >= d && g != 0.0)) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, g,
                         "gravity must be finite, with one component per axis");
            return GR_ERR_VALUE;
        }
        if (g != 0.0 && !(fabs(g) * box_diag <= GR_GRAVITY_GL_MAX)) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, g,
                         "gravity times the box length exceeds 1e280: float64 cannot time a "
                         "flight across a cell; choose units nearer the scene's");
            return GR_ERR_VALUE;
        }
        pulls |= g != 0.0;
    }
    if (pulls && cfg->periodic && !cfg->free_fall) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, NAN,
                     "gravity in a periodic box has no floor: the centre of mass falls forever; "
                     "pass free_fall=True to simulate that frame, or use walls");
        return GR_ERR_VALUE;
    }
    const int32_t n = (int32_t)cfg->n;
    double sigma_max = 0.0;
    for (int32_t i = 0; i < n; i++) {
        if (!(radius[i] > 0.0 && isfinite(radius[i]))) {
            gr_error_set(err, GR_ERR_VALUE, i, -1, NAN, radius[i], "radii must be positive and finite");
            return GR_ERR_VALUE;
        }
        if (!(mass[i] > 0.0 && isfinite(mass[i]))) {
            gr_error_set(err, GR_ERR_VALUE, i, -1, NAN, mass[i], "masses must be positive and finite");
            return GR_ERR_VALUE;
        }
        for (int a = 0; a < d; a++) {
            if (!isfinite(pos[i * d + a]) || !isfinite(vel[i * d + a])) {
                gr_error_set(err, GR_ERR_NONFINITE, i, -1, NAN, NAN, "in the initial positions or velocities");
                return GR_ERR_NONFINITE;
            }
        }
        if (2.0 * radius[i] > sigma_max) sigma_max = 2.0 * radius[i];
    }
    for (int a = 0; a < d; a++) {
        double L = cfg->hi[a] - cfg->lo[a];
        if (!(L > 0.0 && isfinite(L) && isfinite(cfg->lo[a]))) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, L, "the box needs lower < upper, finite, on every axis");
            return GR_ERR_VALUE;
        }
        if (cfg->periodic && !(L > 2.0 * sigma_max)) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, L,
                         "a periodic box must be more than two largest diameters wide on every axis");
            return GR_ERR_VALUE;
        }
        if (!cfg->periodic && !(L >= sigma_max)) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, L,
                         "the box is narrower than the largest particle");
            return GR_ERR_VALUE;
        }
    }
    for (int32_t i = 0; i < n; i++) {
        for (int a = 0; a < d; a++) {
            double x = pos[i * d + a];
            double lo = cfg->lo[a], hi = cfg->hi[a];
            /* walls: the whole disk inside (a relative 1e-12 of slack for rounding);
             * periodic: the centre inside. */
            double slack = 1e-12 * (hi - lo);
            int out = bd_outside(cfg->periodic, x, radius[i], lo, hi, slack);
            if (out) {
                gr_error_set(err, GR_ERR_OUTSIDE, i, -1, NAN, x,
                             cfg->periodic ? "its centre is outside [lower, upper]"
                                           : "it crosses a wall");
                return GR_ERR_OUTSIDE;
            }
        }
    }
    return GR_OK;
}

/* Pairs touching to within a relative 1e-10 are accepted (a configuration built at
 * contact rounds either way); if they approach, the engine collides them at once. */
static int overlap(const double *x, const double *y, const double *shift, double ri,
                   double rj, int dim, int periodic, const double *L, double *depth)
{
    double d2 = 0.0;
    for (int a = 0; a < dim; a++) {
        double d = y[a] + (shift ? shift[a] : 0.0) - x[a];
        if (periodic && !shift) d = bd_nearest(d, L[a]);
        d2 += d * d;
    }
    double sigma = (ri + rj) * (1.0 - 1e-10);
    *depth = ri + rj - sqrt(d2);
    return d2 < sigma * sigma;
}

int gr_find_overlap(int dim, int32_t n, const double *pos, size_t pstride,
                    const double *radius, size_t rstride, int periodic, const double *L,
                    const gr_cells *g, const gr_big *b, gr_error *err)
{
    double depth;
    /* the big particles with everyone, O(N) each */
    for (int32_t k = 0; k < b->n; k++) {
        const int32_t i = b->idx[k];
        for (int32_t j = 0; j < n; j++) {
            if (j == i || (b->is_big[j] && j < i)) continue;
            if (overlap(pos + (size_t)i * pstride, pos + (size_t)j * pstride, NULL,
                        radius[(size_t)i * rstride], radius[(size_t)j * rstride], dim,
                        periodic, L, &depth)) {
                gr_error_set(err, GR_ERR_OVERLAP, i < j ? i : j, i < j ? j : i, 0.0, depth,
                             "in the initial configuration");
                return GR_ERR_OVERLAP;
            }
        }
    }
    /* the others, O(N) through the cells */
    gr_nbr nb[27];
    for (int32_t i = 0; i < n; i++) {
        const double *x = pos + (size_t)i * pstride;
        int32_t c[3] = {0, 0, 0};
        cell_coords(g, dim, x, c);
        int count = cell_neighbours(g, dim, c, -1, 0, nb);
        for (int k = 0; k < count; k++) {
            for (int32_t j = g->head[nb[k].cell]; j >= 0; j = g->next[j]) {
                if (j <= i) continue;
                if (overlap(x, pos + (size_t)j * pstride, nb[k].shift, radius[(size_t)i * rstride],
                            radius[(size_t)j * rstride], dim, periodic, L, &depth)) {
                    gr_error_set(err, GR_ERR_OVERLAP, i, j, 0.0, depth, "in the initial configuration");
                    return GR_ERR_OVERLAP;
                }
            }
        }
    }
    return GR_OK;
}

int gr_edmd_check(const gr_edmd_config *cfg, const double *pos, const double *vel,
                  const double *radius, const double *mass, gr_error *err)
{
    int status = gr_validate_config(cfg, pos, vel, radius, mass, err);
    if (status != GR_OK) return status;
    const int d = cfg->dim;
    const int32_t n = (int32_t)cfg->n;
    double L[3] = {1.0, 1.0, 1.0};
    for (int a = 0; a < d; a++) L[a] = cfg->hi[a] - cfg->lo[a];
    gr_cells g = {0};
    gr_big b = {0};
    b.is_big = calloc((size_t)n, sizeof *b.is_big);
    if (!b.is_big) return GR_ERR_NOMEM;
    status = gr_big_choose(&b, d, n, radius, L, cfg->big_ratio, cfg->cell_factor);
    if (status == GR_OK)
        status = gr_cells_build(&g, d, n, cfg->lo, L, cfg->periodic,
                                2.0 * b.r_small * cfg->cell_factor, err);
    if (status == GR_OK) {
        for (int32_t i = 0; i < n; i++) {
            if (b.is_big[i]) continue;
            int32_t c[3] = {0, 0, 0};
            cell_coords(&g, d, pos + (size_t)i * d, c);
            cell_insert(&g, i, cell_of(&g, d, c));
        }
        status = gr_find_overlap(d, n, pos, (size_t)d, radius, 1, cfg->periodic, L, &g, &b, err);
    }
    gr_cells_free(&g);
    free(b.is_big);
    return status;
}
