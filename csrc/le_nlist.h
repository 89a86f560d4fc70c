/* le_nlist.h -- neighbour lists in a sheared (Lees-Edwards) box: the list search (the
 * centres carried by the flow, le_cells.h), the scan through the sliding images, the
 * shells' exits and lives.  Why these keep the lists exact is in nlist.h.
 *
 * Static functions included by search.h (so by edmd.c only), reached only when the box
 * is sheared (s->le): the plain loop never runs them.  In 3D on AVX2 CPUs the scan runs
 * in four lanes instead (scan_avx2.h scan_list_avx2_sheared, the same bits). */
#ifndef GR_LE_NLIST_H
#define GR_LE_NLIST_H

#include <math.h>

#include "engine.h"

#ifdef GR_SCAN_X86
/* for a mask of the lanes kept: those lanes in order (then lane 0), and how many */
static const int32_t le_pack[16][4] = {
    {0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0},
    {1, 2, 0, 0}, {0, 1, 2, 0}, {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0},
    {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3}};
static const int32_t le_kept[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

/* le_test_scalar (le_cells.h) in 3D, four candidates at a time in AVX2's lanes: each
 * lane takes le_within's steps in its order, so passes exactly when it does; the lanes
 * that pass are appended in order.  A short last group is padded (le_test_padded) and
 * masked. */
static GR_AVX2 inline int32_t le_test_avx2(const gr_edmd *s, int dim, const le_batch *b,
                                           int32_t *out, int32_t m)
{
    (void)dim;
    const double *centre = s->nl.centre;
    const int8_t *lap = s->nl.lap;
    const __m128i inbox = _mm_set1_epi32(-b->inbox);
    const __m256d theta = _mm256_set1_pd(b->theta), sweep = _mm256_set1_pd(b->sweep),
                  yoff = _mm256_set1_pd(b->yoff), zoff = _mm256_set1_pd(b->zoff),
                  reach = _mm256_set1_pd(b->reach), scale = _mm256_set1_pd(b->scale),
                  xline = _mm256_set1_pd(b->xline), lx = _mm256_set1_pd(b->lx),
                  zero = _mm256_setzero_pd();
    const __m128i code1 = _mm_set1_epi32(b->code1);
    for (int k = 0; k < b->n; k += 4) {
        const double *q[4];
        for (int l = 0; l < 4; l++) q[l] = centre + (size_t)4 * b->j[k + l]; /* padded */
        __m256d X, Y, Z, R;
        GR_TRANSPOSE4(_mm256_load_pd(q[0]), _mm256_load_pd(q[1]), _mm256_load_pd(q[2]),
                      _mm256_load_pd(q[3]), X, Y, Z, R);
        int32_t w4; /* the lanes' wraps */
        memcpy(&w4, b->wrap + k, sizeof w4);
        const __m128i W = _mm_cvtepi8_epi32(_mm_cvtsi32_si128(w4));
        const __m256d xoff = _mm256_add_pd(xline, _mm256_mul_pd(_mm256_cvtepi32_pd(W), lx));
        const __m256d dx = _mm256_add_pd(_mm256_add_pd(X, _mm256_mul_pd(theta, Y)), xoff);
        const __m256d dy = _mm256_add_pd(Y, yoff);
        const __m256d end = _mm256_add_pd(dx, _mm256_mul_pd(sweep, dy));
        const __m256d dx2 = _mm256_mul_pd(dx, dx), end2 = _mm256_mul_pd(end, end);
        const __m256d passes = _mm256_cmp_pd(_mm256_mul_pd(dx, end), zero, _CMP_LE_OQ);
        /* dx2 < end2 ? dx2 : end2, as _mm256_min_pd picks */
        const __m256d least = _mm256_blendv_pd(_mm256_min_pd(dx2, end2), zero, passes);
        const __m256d dz = _mm256_add_pd(Z, zoff);
        const __m256d d2 = _mm256_add_pd(_mm256_add_pd(least, _mm256_mul_pd(dy, dy)),
                                         _mm256_mul_pd(dz, dz));
        const __m256d cut = _mm256_mul_pd(scale, _mm256_add_pd(R, reach));
        int mask = _mm256_movemask_pd(_mm256_cmp_pd(d2, _mm256_mul_pd(cut, cut), _CMP_LT_OQ));
        const int rest = b->n - k; /* the last group's lanes past n, without a branch */
        mask &= 15 >> (4 - (rest < 4 ? rest : 4));
        /* the entries (le_append), those kept packed to the front without a branch */
        const __m128i J = _mm_loadu_si128((const __m128i *)(b->j + k));
        const __m128i self = _mm_set1_epi32(b->self);
        mask &= b->above ? _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(J, self)))
                         : ~_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(J, self)));
        const __m128i laps = _mm_and_si128(
            _mm_setr_epi32(lap[b->j[k]], lap[b->j[k + 1]], lap[b->j[k + 2]], lap[b->j[k + 3]]),
            inbox);
        const __m128i E = _mm_or_si128(
            _mm_slli_epi32(J, GR_NL_BITS),
            _mm_sub_epi32(_mm_add_epi32(code1, _mm_and_si128(W, inbox)), laps));
        const __m128i packed = _mm_castps_si128(_mm_permutevar_ps(
            _mm_castsi128_ps(E), _mm_loadu_si128((const __m128i *)le_pack[mask & 15])));
        _mm_storeu_si128((__m128i *)(out + m), packed);
        m += le_kept[mask & 15];
    }
    return m;
}
#endif

#ifdef GR_SCAN_X86
/* le_gather compiled for AVX2, its batches' test inlined (3D) */
static GR_AVX2 int32_t le_gather_avx2(gr_edmd *s, const double *point, double t, int32_t i,
                                      int above)
{
    return le_gather(s, 3, point, t, i, above, 1.0, s->nl.near, le_test_avx2);
}
#endif

/* find_near in a sheared box, from i's position (its new centre) at its clock
 * (le_cells.h), in AVX2's lanes in 3D on CPUs that have them (the same bits). */
static int32_t le_find_near(gr_edmd *s, int dim, int32_t i, int above)
{
    const double *p = rec(s, dim, i);
    const double point[4] = {p[0], p[1], dim == 3 ? p[2] : RAD(p, dim), RAD(p, dim)};
#ifdef GR_SCAN_X86
    if (dim == 3 && gr_scan_avx2) return le_gather_avx2(s, point, TIME(p, dim), i, above);
#endif
    return le_gather(s, dim, point, TIME(p, dim), i, above, 1.0, s->nl.near, le_test_scalar);
}

/* File every list centre anew where the flow carries it at t + span (le_cells.h), so
 * that searches from t to t + 2 span see a window widened by a strain of at most
 * GR_NL_TILT. */
static void le_refile(gr_edmd *s, int dim, double t)
{
    gr_cells *g = &s->cells;
    gr_nlist *nl = &s->nl;
    const double tref = nl->tref;
    nl->tref = t + nl->span;
    nl->dref = bd_le_offset(s->cfg.shear_offset, s->le_u, nl->tref, nl->lx);
    gr_cells_clear(g);
    for (int32_t i = s->n - 1; i >= 0; i--) { /* each cell's list in increasing order */
        gr_sched *e = &s->sched[i];
        double *c = nl->centre + (size_t)i * (dim + 1);
        e->c[0] = le_file(g, nl, c, &nl->lap[i], c[0] + (double)nl->lap[i] * nl->lx, tref);
        cell_insert(g, i, cell_of(g, dim, e->c));
    }
    le_sync_all(g, nl->blocks);
}

/* One listed candidate j through a y face (image shift sh: y and z; ky = sign of its y):
 * as try_pair, with the x image nearest now, displaced by ky delta, and moving with ky u
 * (as do_pair_sheared finds it at the collision). */
static inline void le_try_listed(const gr_edmd *s, int dyn, int dim, int32_t i, const double *p,
                                 int32_t j, const double *sh, double delta, double *best,
                                 int32_t *partner)
{
    const double *q = rec(s, dim, j);
    const double ky = sh[1] > 0.0 ? 1.0 : -1.0;
    double dtj = TIME(p, dim) - TIME(q, dim), dr[3], dv[3];
    for (int a = 0; a < dim; a++) {
        dr[a] = fl_sep(dyn, q[a], VEL(q, dim)[a], s->cfg.gravity[a], dtj, p[a]);
        if (a) dr[a] += sh[a];
        dv[a] = fl_relvel(dyn, VEL(q, dim)[a], VEL(p, dim)[a], s->cfg.gravity[a], dtj);
    }
    /* positions stray up to a shell beyond the box: |dr| < 3 L / 2 for each nearest */
    dr[0] = bd_nearest(bd_nearest(dr[0], s->L[0]) + ky * delta, s->L[0]);
    dv[0] += ky * s->le_u;
    double dt;
    if (!fl_pair_beats(dyn, dim, dr, dv, RAD(p, dim) + RAD(q, dim), *best, &dt)) return;
    if (rebound_now(s, i, j, TIME(p, dim), dt)) return;
    *best = dt;
    *partner = j;
}

/* scan_list in a sheared box: entries within the box or through an x or z face as
 * there, those through a y face through the sliding image. */
static void le_scan_list(gr_edmd *s, int dyn, int dim, int32_t i)
{
    const double *p = rec(s, dim, i);
    gr_sched *e = &s->sched[i];
    const int32_t *row = nl_row(&s->nl, i);
    const double delta = bd_le_offset(s->cfg.shear_offset, s->le_u, TIME(p, dim), s->L[0]);
    double best = (e->t_coll < e->t_cross ? e->t_coll : e->t_cross) - TIME(p, dim);
    int32_t partner = -1;
    for (int k = 0; k < e->nn; k++) {
        const int32_t j = row[k] >> GR_NL_BITS;
        const double *sh = s->nl.img[row[k] & GR_NL_CODE_MASK];
        if (sh[1] == 0.0) try_pair(s, dyn, dim, i, p, j, sh, 0, &best, &partner);
        else le_try_listed(s, dyn, dim, i, p, j, sh, delta, &best, &partner);
    }
    keep_pair(s, dim, i, best, partner);
}

/* List mode in a sheared box, i's clock at the present: its shell exit (nlist.h), when
 * it leaves the shell about its centre carried by the flow, or when the list's life ends
 * (the strain it may last, and the drift of its centre); edmd.c predict then scans its
 * list.  The radius and the end are the list's (le_expiry). */
static void le_shell_exit(gr_edmd *s, int dyn, int dim, int32_t i)
{
    const gr_nlist *nl = &s->nl;
    const double *p = rec(s, dim, i), *c = nl->centre + (size_t)i * (dim + 1);
    const double t = TIME(p, dim), *expiry = nl->expiry + 2 * (size_t)i;
    const double w = nl->rate * (c[1] - nl->yc); /* the flow at the centre */
    double centre[3], v[3];
    for (int a = 0; a < dim; a++) {
        centre[a] = c[a];
        v[a] = VEL(p, dim)[a];
    }
    centre[0] = le_centre_x(nl, c, nl->lap[i], t);
    v[0] -= w;
    const double radius = expiry[1];
    double exit = radius > 0.0 ? fl_exit_time(dyn, dim, p, v, s->cfg.gravity, centre,
                                              radius * radius)
                               : 0.0;
    const double left = expiry[0] - t;
    if (left < exit) exit = left > 0.0 ? left : 0.0;
    s->sched[i].t_cross = t + exit;
}

#endif
