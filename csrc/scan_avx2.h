/* scan_avx2.h -- the 3D list scan (search.h, scan_list) four candidates at a time, in
 * AVX2's lanes, for x86-64 CPUs that have it; included by search.h only.
 *
 * Why: at packing 0.45 the scans are ~40 % of an event's time, ~70 instructions a
 * candidate, nearly all of them arithmetic that is the same for every candidate.
 *
 * Same bits as the scalar scan.  Each lane does try_pair's and gr_pair_beats' operations
 * in their order (no multiply-add: the target has no FMA, and C99 forbids contracting
 * anyway), so its b, c, disc and t are the scalar values exactly.  The lanes test against
 * the horizon at the start of their group of four; a candidate that passes there is then
 * tested in order, in scalar, against the best so far, as the scalar loop would.  Nothing
 * the scalar loop keeps is dropped: with b < 0 the test c < -2 b h can only fail for a
 * smaller h (rounded products are monotonic), and t < h likewise.
 *
 * The records are one aligned cache line, x y z vx | vy vz t r: two loads each, and a
 * 4 x 4 transpose turns four of them into a vector per field. */
#ifndef GR_SCAN_AVX2_H
#define GR_SCAN_AVX2_H

#if defined(__x86_64__) && (defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 6))
#define GR_SCAN_X86 1
#include <immintrin.h>

#define GR_AVX2 __attribute__((target("avx2")))

/* rows r0..r3 of four doubles -> columns c0..c3 */
#define GR_TRANSPOSE4(r0, r1, r2, r3, c0, c1, c2, c3)                                   \
    do {                                                                                \
        const __m256d t0_ = _mm256_unpacklo_pd(r0, r1), t1_ = _mm256_unpackhi_pd(r0, r1); \
        const __m256d t2_ = _mm256_unpacklo_pd(r2, r3), t3_ = _mm256_unpackhi_pd(r2, r3); \
        c0 = _mm256_permute2f128_pd(t0_, t2_, 0x20);                                    \
        c1 = _mm256_permute2f128_pd(t1_, t3_, 0x20);                                    \
        c2 = _mm256_permute2f128_pd(t0_, t2_, 0x31);                                    \
        c3 = _mm256_permute2f128_pd(t1_, t3_, 0x31);                                    \
    } while (0)

/* a separation along one axis, as try_pair forms it: the free flight's (flight.h,
 * GR_FL_SEP) in four lanes, then the image shift */
static GR_AVX2 inline __m256d sep4(__m256d q, __m256d vq, __m256d dtj, __m256d p, __m256d shift)
{
    return _mm256_add_pd(GR_FL_SEP(_mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd, q, vq, dtj, p),
                         shift);
}

/* a 3-vector dot product summed as gr_pair_beats sums it: (a0 b0 + a1 b1) + a2 b2 */
static GR_AVX2 inline __m256d dot4(__m256d a0, __m256d a1, __m256d a2, __m256d b0, __m256d b1,
                                   __m256d b2)
{
    return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a0, b0), _mm256_mul_pd(a1, b1)),
                         _mm256_mul_pd(a2, b2));
}

/* bd_nearest (boundary.h) in four lanes, the same bits: d - L above L/2, d + L below -L/2 */
static GR_AVX2 inline __m256d nearest4(__m256d d, __m256d L, __m256d half)
{
    const __m256d up = _mm256_cmp_pd(d, half, _CMP_GT_OQ);
    const __m256d down = _mm256_cmp_pd(d, _mm256_xor_pd(half, _mm256_set1_pd(-0.0)), _CMP_LT_OQ);
    return _mm256_blendv_pd(_mm256_blendv_pd(d, _mm256_sub_pd(d, L), up), _mm256_add_pd(d, L),
                            down);
}

/* The loop, for a box with fixed images (sheared = 0: scan_list_avx2) or a sheared box's
 * lists (sheared = 1: scan_list_avx2_sheared, le_nlist.h), whose entries through a y face
 * (a lane whose y shift is not 0) take x as le_try_listed does -- the nearest image of
 * the separation, displaced by ky delta, nearest again -- and v_x + ky u; the other lanes
 * as the plain loop, chosen per lane by a blend (exact: no arithmetic on the kept value). */
static GR_AVX2 GR_ALWAYS_INLINE void scan_list_avx2_in(gr_edmd *s, int32_t i, const int sheared)
{
    const int dim = 3;
    const double *p = rec(s, dim, i);
    gr_sched *e = &s->sched[i];
    const int32_t *row = nl_row(&s->nl, i);
    double best = (e->t_coll < e->t_cross ? e->t_coll : e->t_cross) - TIME(p, dim);
    int32_t partner = -1;
    const __m256d px = _mm256_set1_pd(p[0]), py = _mm256_set1_pd(p[1]),
                  pz = _mm256_set1_pd(p[2]), pvx = _mm256_set1_pd(p[3]),
                  pvy = _mm256_set1_pd(p[4]), pvz = _mm256_set1_pd(p[5]),
                  pt = _mm256_set1_pd(TIME(p, dim)), pr = _mm256_set1_pd(RAD(p, dim));
    const __m256d zero = _mm256_setzero_pd(), m2 = _mm256_set1_pd(-2.0),
                  sign = _mm256_set1_pd(-0.0);
    /* a sheared box: +-delta now, +-u, L_x and L_x / 2 (unused otherwise) */
    const double delta =
        sheared ? bd_le_offset(s->cfg.shear_offset, s->le_u, TIME(p, dim), s->L[0]) : 0.0;
    const __m256d le_d = _mm256_set1_pd(delta), le_md = _mm256_set1_pd(-delta),
                  le_u = _mm256_set1_pd(s->le_u), le_mu = _mm256_set1_pd(-s->le_u),
                  lx = _mm256_set1_pd(s->L[0]), hx = _mm256_set1_pd(0.5 * s->L[0]);
    (void)le_d, (void)le_md, (void)le_u, (void)le_mu, (void)lx, (void)hx;
    /* a short group is filled with i itself, which never passes (b = 0) */
    const int32_t self = (i << GR_NL_BITS) | GR_NL_CODE_NONE(dim);
    const int nn = e->nn;
    for (int k = 0; k < nn; k += 4) {
        int32_t ent[4], j[4];
        const double *q[4], *sh[4];
        for (int l = 0; l < 4; l++) {
            ent[l] = k + l < nn ? row[k + l] : self;
            j[l] = ent[l] >> GR_NL_BITS;
            q[l] = rec(s, dim, j[l]);
            sh[l] = s->nl.img[ent[l] & GR_NL_CODE_MASK];
        }
        __m256d X, Y, Z, VX, VY, VZ, T, R, SX, SY, SZ, S3;
        GR_TRANSPOSE4(_mm256_load_pd(q[0]), _mm256_load_pd(q[1]), _mm256_load_pd(q[2]),
                      _mm256_load_pd(q[3]), X, Y, Z, VX);
        GR_TRANSPOSE4(_mm256_load_pd(q[0] + 4), _mm256_load_pd(q[1] + 4),
                      _mm256_load_pd(q[2] + 4), _mm256_load_pd(q[3] + 4), VY, VZ, T, R);
        GR_TRANSPOSE4(_mm256_loadu_pd(sh[0]), _mm256_loadu_pd(sh[1]), _mm256_loadu_pd(sh[2]),
                      _mm256_loadu_pd(sh[3]), SX, SY, SZ, S3);
        (void)S3;
        const __m256d dtj = _mm256_sub_pd(pt, T);
        __m256d dx = sep4(X, VX, dtj, px, SX);
        const __m256d dy = sep4(Y, VY, dtj, py, SY), dz = sep4(Z, VZ, dtj, pz, SZ);
        __m256d ux = _mm256_sub_pd(VX, pvx);
        const __m256d uy = _mm256_sub_pd(VY, pvy), uz = _mm256_sub_pd(VZ, pvz);
        if (sheared) { /* lanes through a y face: the sliding image (le_try_listed) */
            const __m256d pos = _mm256_cmp_pd(SY, zero, _CMP_GT_OQ),
                          neg = _mm256_cmp_pd(SY, zero, _CMP_LT_OQ), face = _mm256_or_pd(pos, neg);
            const __m256d kd = _mm256_or_pd(_mm256_and_pd(pos, le_d), _mm256_and_pd(neg, le_md));
            const __m256d ku = _mm256_or_pd(_mm256_and_pd(pos, le_u), _mm256_and_pd(neg, le_mu));
            const __m256d raw = GR_FL_SEP(_mm256_add_pd, _mm256_sub_pd, _mm256_mul_pd, X, VX, dtj, px);
            const __m256d fx = nearest4(_mm256_add_pd(nearest4(raw, lx, hx), kd), lx, hx);
            dx = _mm256_blendv_pd(dx, fx, face);
            ux = _mm256_blendv_pd(ux, _mm256_add_pd(ux, ku), face);
        }
        const __m256d b = dot4(dx, dy, dz, ux, uy, uz), dr2 = dot4(dx, dy, dz, dx, dy, dz),
                      dv2 = dot4(ux, uy, uz, ux, uy, uz);
        const __m256d sigma = _mm256_add_pd(pr, R);
        const __m256d c = _mm256_sub_pd(dr2, _mm256_mul_pd(sigma, sigma));
        const __m256d disc = _mm256_sub_pd(_mm256_mul_pd(b, b), _mm256_mul_pd(dv2, c));
        const __m256d h = _mm256_set1_pd(best);
        const __m256d touching = _mm256_cmp_pd(c, zero, _CMP_LE_OQ);
        const __m256d soon = _mm256_and_pd(
            _mm256_cmp_pd(c, _mm256_mul_pd(_mm256_mul_pd(m2, b), h), _CMP_LT_OQ),
            _mm256_cmp_pd(disc, zero, _CMP_GT_OQ));
        const __m256d pass = _mm256_and_pd(_mm256_cmp_pd(b, zero, _CMP_LT_OQ),
                                           _mm256_or_pd(touching, soon));
        if (!_mm256_movemask_pd(pass)) continue;
        const __m256d root = _mm256_div_pd(
            c, _mm256_add_pd(_mm256_xor_pd(b, sign), _mm256_sqrt_pd(disc)));
        const __m256d t = _mm256_blendv_pd(root, zero, touching);
        int mask = _mm256_movemask_pd(_mm256_and_pd(pass, _mm256_cmp_pd(t, h, _CMP_LT_OQ)));
        if (!mask) continue;
        double tl[4], bl[4], cl[4], dl[4];
        _mm256_storeu_pd(tl, t);
        _mm256_storeu_pd(bl, b);
        _mm256_storeu_pd(cl, c);
        _mm256_storeu_pd(dl, disc);
        for (; mask; mask &= mask - 1) {
            const int l = __builtin_ctz(mask);
            /* gr_pair_beats' test against the best so far, on the lane's values */
            if (!gr_pair_may_beat(bl[l], cl[l], dl[l], best) || !(tl[l] < best)) continue;
            if (rebound_now(s, i, j[l], TIME(p, dim), tl[l])) continue;
            best = tl[l];
            partner = j[l];
            GR_PREFETCH(&s->sched[j[l]]);
        }
    }
    keep_pair(s, dim, i, best, partner);
}

static GR_AVX2 void scan_list_avx2(gr_edmd *s, int32_t i) { scan_list_avx2_in(s, i, 0); }

/* a sheared box's lists (le_nlist.h), the same bits as le_scan_list */
static GR_AVX2 void scan_list_avx2_sheared(gr_edmd *s, int32_t i) { scan_list_avx2_in(s, i, 1); }
#endif

#endif
