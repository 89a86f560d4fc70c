/* validate.c -- is a configuration one the engine can start from?  Arguments in range,
 * finite numbers, everyone in the box, no two particles overlapping.  Used by
 * gr_edmd_new and, without building an engine, by gr_edmd_check. */
#include <math.h>
#include <stdlib.h>

#include "drive.h"
#include "engine.h"
#include "vibwall.h"

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

/* Lees-Edwards (boundary.h): a periodic box; an offset in [0, L_x); image speeds
 * u = shear_rate L_y that double arithmetic can carry: |u| in [1e-140, 1e140] (the
 * scene's speeds' range), and at most 2^26 times the fastest initial speed where any
 * particle moves (a crossing adds u to v_x and takes it off again: past that, fewer than
 * 26 bits of the velocity would survive it). */
static int validate_shear(const gr_edmd_config *cfg, const double *vel, gr_error *err)
{
    if (!isfinite(cfg->shear_rate) || !isfinite(cfg->shear_offset)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN,
                     isfinite(cfg->shear_rate) ? cfg->shear_offset : cfg->shear_rate,
                     "shear_rate and shear_offset must be finite");
        return GR_ERR_VALUE;
    }
    if (cfg->shear_rate == 0.0 && cfg->shear_offset == 0.0) return GR_OK;
    if (!cfg->periodic) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->shear_rate,
                     "shear (Lees-Edwards images) needs a periodic box: walls on the gradient "
                     "axis y cannot slide");
        return GR_ERR_VALUE;
    }
    const double Lx = cfg->hi[0] - cfg->lo[0], u = cfg->shear_rate * (cfg->hi[1] - cfg->lo[1]);
    if (!(cfg->shear_offset >= 0.0 && cfg->shear_offset < Lx)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->shear_offset,
                     "shear_offset must lie in [0, L_x) (the box length along x)");
        return GR_ERR_VALUE;
    }
    if (cfg->shear_rate == 0.0) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->shear_offset,
                     "shear_offset != 0 needs a shear rate (images displaced but at rest are "
                     "not offered)");
        return GR_ERR_VALUE;
    }
    if (!(fabs(u) >= 1e-140 && fabs(u) <= 1e140)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, u,
                     "the sheared images' speed |shear_rate| L_y must lie in [1e-140, 1e140]");
        return GR_ERR_VALUE;
    }
    double vmax = 0.0;
    for (int64_t k = 0; k < cfg->n * cfg->dim; k++)
        if (fabs(vel[k]) > vmax) vmax = fabs(vel[k]);
    if (vmax > 0.0 && fabs(u) > 0x1p26 * vmax) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, u,
                     "the sheared images' speed |shear_rate| L_y is more than 2^26 times the "
                     "fastest particle's: a face crossing would round the velocities away");
        return GR_ERR_VALUE;
    }
    return GR_OK;
}

/* A vibrating wall (vibwall.h) the engine can run: on a walled box's axis, its numbers
 * finite and positive, a particle's width of room between the wall at its innermost and the
 * opposite face, and every particle on the box's side of the wall at t = 0 (with slack for
 * the rounding of a phase carried over from a running engine: Simulation.scene). */
static int validate_vibwall(const gr_edmd_config *cfg, const double *pos, const double *radius,
                            double sigma_max, gr_error *err)
{
    const gr_vibwall *w = &cfg->vib;
    const char *why = NULL;
    double value = NAN;
    if (cfg->periodic) why = "a vibrating wall needs walls (boundary='walls')";
    else if (w->axis < 0 || w->axis >= cfg->dim) {
        why = "a vibrating wall's axis must be 0 .. dim - 1";
        value = w->axis;
    } else if (w->side != 0 && w->side != 1) {
        why = "a vibrating wall's side must be 0 (lower) or 1 (upper)";
        value = w->side;
    } else if (w->waveform != GR_WAVE_SINE && w->waveform != GR_WAVE_TRIANGLE) {
        why = "a vibrating wall's waveform must be sine or triangle";
        value = w->waveform;
    } else if (!(w->amplitude > 0.0 && isfinite(w->amplitude))) {
        why = "a vibrating wall's amplitude must be positive and finite";
        value = w->amplitude;
    } else if (!(w->omega > 0.0 && isfinite(w->omega) && isfinite(w->amplitude * w->omega) &&
                 isfinite(w->amplitude * w->omega * w->omega))) {
        why = "a vibrating wall's angular frequency must be positive and finite (and A omega^2 too)";
        value = w->omega;
    } else if (!(fabs(w->phase) <= 2.0 * GR_VW_PI)) {
        /* the wall is timed by omega t + phase: a large phase's rounding would swamp it
         * (granular.VibratingWall keeps its phase modulo 2 pi) */
        why = "a vibrating wall's phase must lie in [-2 pi, 2 pi]";
        value = w->phase;
    } else if (!(2.0 * w->amplitude + sigma_max < cfg->hi[w->axis] - cfg->lo[w->axis])) {
        why = "a vibrating wall's sweep (2 A) plus the largest diameter must be less than the "
              "box's length along its axis: the wall at its innermost must leave room for a "
              "particle";
        value = w->amplitude;
    }
    if (why) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, value, why);
        return GR_ERR_VALUE;
    }
    const int a = w->axis, d = cfg->dim;
    const double X = vw_position(w, cfg->lo[a], cfg->hi[a], 0.0);
    const double slack = 1e-12 * (cfg->hi[a] - cfg->lo[a]) + 0x1p-24 * w->amplitude;
    for (int32_t i = 0; i < (int32_t)cfg->n; i++) {
        const double x = pos[(size_t)i * d + a], r = radius[i];
        if (w->side ? x + r > X + slack : x - r < X - slack) {
            gr_error_set(err, GR_ERR_OUTSIDE, i, -1, NAN, x,
                         "it crosses the vibrating wall (at its position at t = 0)");
            return GR_ERR_OUTSIDE;
        }
    }
    return GR_OK;
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
    status = gr_drive_check(cfg, err);
    if (status != GR_OK) return status;
    /* rough particles (rule.h) */
    if (!(cfg->tangential_restitution >= -1.0 && cfg->tangential_restitution <= 1.0)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->tangential_restitution,
                     "tangential restitution must lie in [-1, 1]");
        return GR_ERR_VALUE;
    }
    if (!(cfg->inertia_factor > 0.0 && cfg->inertia_factor <= 1.0)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->inertia_factor,
                     "inertia factor q (I = q m r^2) must lie in (0, 1]");
        return GR_ERR_VALUE;
    }
    if (!(cfg->friction >= 0.0)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->friction,
                     "friction must be >= 0 (inf: no Coulomb limit)");
        return GR_ERR_VALUE;
    }
    if (cfg->spin)
        for (int64_t k = 0; k < cfg->n * GR_SPIN_DIM(d); k++)
            if (!(fabs(cfg->spin[k]) <= 1e140)) {
                gr_error_set(err, GR_ERR_NONFINITE, k / GR_SPIN_DIM(d), -1, NAN, cfg->spin[k],
                             "in the initial angular velocities");
                return GR_ERR_NONFINITE;
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
    /* gravity's loops (edmd_gravity.c, edmd_gravity_rough.c) have no sliding images' slide
     * events.  A sheared box is periodic, where gravity is the free-fall frame only
     * (docs/gravity.md, "Gravity and shear"): along x or z that is the sheared gas's own
     * motion plus g t^2 / 2 for everyone, a change of frame that adds no physics; along the
     * gradient y the falling gas would cross the sliding faces, each crossing shifting v_x
     * by the images' speed, which no falling frame undoes */
    const char *unlike =
        !pulls ? NULL
        : cfg->shear_rate != 0.0 && cfg->gravity[1] != 0.0
            ? "gravity along the shear gradient y is refused in a sheared box: the falling "
              "gas would cross the sliding y faces, each crossing shifting v_x by the images' "
              "speed (no falling frame carries the Lees-Edwards images)"
        : cfg->shear_rate != 0.0
            ? "gravity is not offered in a sheared box: a sheared box is periodic, where g "
              "along x or z is only the free-fall frame, the same motion as without gravity "
              "plus g t^2 / 2 for every particle (simulate without gravity and add it)"
        : NULL;
    if (unlike) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, NAN, unlike);
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
    int status_le = validate_shear(cfg, vel, err);
    if (status_le != GR_OK) return status_le;
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
    if (cfg->vib.on) return validate_vibwall(cfg, pos, radius, sigma_max, err);
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

/* Sheared box (boundary.h), for gr_find_overlap: the pairs across the y faces, through
 * the image across the upper face displaced by offset along x.  Each particle of the top
 * row of cells looks at the bottom row's columns whose images overlap its neighbours'
 * (the window of lees_edwards.h, one column to spare each way). */
static int find_overlap_sheared(int dim, int32_t n, const double *pos, size_t pstride,
                                const double *radius, size_t rstride, const double *L,
                                const gr_cells *g, double offset, gr_error *err)
{
    const int32_t nx = g->nc[0], M = (int32_t)floor(offset / g->w[0]);
    for (int32_t i = 0; i < n; i++) {
        const double *x = pos + (size_t)i * pstride;
        int32_t c[3] = {0, 0, 0};
        cell_coords(g, dim, x, c);
        if (c[1] != g->nc[1] - 1) continue;
        for (int kz = 0; kz < (dim == 3 ? 3 : 1); kz++) {
            const int32_t q2 = dim == 3 ? g->nb_cell[2][3 * c[2] + kz] : 0;
            double shift[3] = {0.0, L[1], dim == 3 ? g->nb_shift[2][3 * c[2] + kz] : 0.0};
            for (int32_t K = c[0] - M - 3; K <= c[0] - M + 2; K++) {
                const int32_t k = bd_cell_wrap(K, nx), q[3] = {k, 0, q2};
                shift[0] = offset + (double)((K - k) / nx) * L[0];
                for (int32_t j = g->head[cell_of(g, dim, q)]; j >= 0; j = g->next[j]) {
                    double depth;
                    if (j != i && overlap(x, pos + (size_t)j * pstride, shift,
                                          radius[(size_t)i * rstride], radius[(size_t)j * rstride],
                                          dim, 1, L, &depth)) {
                        gr_error_set(err, GR_ERR_OVERLAP, i < j ? i : j, i < j ? j : i, 0.0,
                                     depth, "in the initial configuration (through the sheared images)");
                        return GR_ERR_OVERLAP;
                    }
                }
            }
        }
    }
    return GR_OK;
}

int gr_find_overlap(int dim, int32_t n, const double *pos, size_t pstride,
                    const double *radius, size_t rstride, int periodic, const double *L,
                    const gr_cells *g, const gr_big *b, const double *sheared, gr_error *err)
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
            if (sheared && nb[k].shift[1] != 0.0) continue; /* across a y face: below */
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
    if (sheared) return find_overlap_sheared(dim, n, pos, pstride, radius, rstride, L, g, *sheared, err);
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
    const int sheared = cfg->periodic && cfg->shear_rate != 0.0;
    status = gr_big_choose(&b, d, n, radius, L, sheared ? INFINITY : cfg->big_ratio, cfg->cell_factor);
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
        status = gr_find_overlap(d, n, pos, (size_t)d, radius, 1, cfg->periodic, L, &g, &b,
                                 sheared ? &cfg->shear_offset : NULL, err);
    }
    gr_cells_free(&g);
    free(b.is_big);
    return status;
}
