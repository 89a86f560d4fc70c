/* rng.c -- ziggurat tables, the rare slow path of gr_normal, and the batched normals
 * (see rng.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rng.h"

uint32_t gr_zig_k[128];
double gr_zig_w[128], gr_zig_f[128];

int gr_rng_ready = 0;

/* zig_a[i] = -dn_i^2 / 2 for the layer's edge dn_i, the very double whose exp is
 * gr_zig_f[i] (i >= 1): the anchor of the wedge test's bracket (below_exp). */
static double zig_a[128];

static void pick_batch_kernel(void);

/* Marsaglia & Tsang (2000), 128 layers: r is the start of the tail, v the area of each
 * layer.  The binding calls this once at import, before any thread can draw. */
void gr_rng_init(void)
{
    if (gr_rng_ready) return;
    const double m1 = 2147483648.0, vn = 9.91256303526217e-3;
    double dn = 3.442619855899, tn = dn;
    double q = vn / exp(-0.5 * dn * dn);
    gr_zig_k[0] = (uint32_t)((dn / q) * m1);
    gr_zig_k[1] = 0;
    gr_zig_w[0] = q / m1;
    gr_zig_w[127] = dn / m1;
    gr_zig_f[0] = 1.0;
    zig_a[127] = -0.5 * dn * dn;
    gr_zig_f[127] = exp(zig_a[127]);
    for (int i = 126; i >= 1; i--) {
        dn = sqrt(-2.0 * log(vn / dn + exp(-0.5 * dn * dn)));
        gr_zig_k[i + 1] = (uint32_t)((dn / tn) * m1);
        tn = dn;
        zig_a[i] = -0.5 * dn * dn;
        gr_zig_f[i] = exp(zig_a[i]);
        gr_zig_w[i] = dn / m1;
    }
    pick_batch_kernel();
    gr_rng_ready = 1;
}

/* The wedge test of layer iz >= 1, y < exp(a) for a = -x^2/2 with x = hz w[iz] -- the
 * same answer for every y and every x of the layer, calling exp only when a cheap
 * bracket of e^a cannot tell.
 *
 * Why the answer is the same.  |x| <= dn (|hz| <= 2^31, w[iz] = dn / 2^31), so a >=
 * zig_a[iz] = a0 (-0.5 x and -0.5 dn are exact, the rounding of their products monotone),
 * and e^a = e^a0 e^t with t = a - a0 >= 0.  For t >= 0 Taylor's terms are positive and
 * Lagrange's remainder gives P(t) <= e^t <= P(t) + t^4 e^t / 24, P(t) = 1 + t + t^2/2 +
 * t^3/6, with e^t / 24 <= e^0.75 / 24 < 0.09 for t <= 0.75 (the widest wedge, layer 127,
 * has t < 0.732; beyond 0.75 exp decides).  f = gr_zig_f[iz] is the C library's exp(a0),
 * within 1 ulp of e^a0 (relative 2^-52; glibc's exp is, as are the other common ones),
 * as exp(a) is of e^a; t is computed with relative error <= 2^-53, lo and hi below with
 * fewer than 10 roundings of 2^-53 each.  So lo = f P(t) and hi = f (P(t) + 0.09 t^4)
 * are within 2e-15 relative of a lower and an upper bound of e^a: y < lo (1 - 1e-12)
 * implies y < exp(a), and y > hi (1 + 1e-12) implies y > exp(a) -- the margin of 1e-12
 * is hundreds of times all those errors together.  Between the two, a band of relative
 * width about 0.09 t^4 + 2e-12, exp itself decides: measured, in 1.2e-4 of the wedge
 * tests (762 of 6.55 million, 3.2e-6 of all draws of the exact scheme). */
static inline int below_exp(double y, double a, int iz)
{
    const double t = a - zig_a[iz];
    if (t >= 0.0 && t <= 0.75) {
        const double t2 = t * t; /* P in Estrin's order: a shorter chain than Horner's */
        const double lo = gr_zig_f[iz] * ((1.0 + t) + t2 * (0.5 + t * (1.0 / 6.0)));
        if (y < lo * (1.0 - 1e-12)) return 1;
        if (y > (lo + gr_zig_f[iz] * (0.09 * (t2 * t2))) * (1.0 + 1e-12)) return 0;
    }
    return y < exp(a);
}

double gr_normal_tail(gr_stream *s, int64_t hz, int iz)
{
    const double r = 3.442619855899;
    for (;;) {
        double x = hz * gr_zig_w[iz];
        if (iz == 0) { /* the tail beyond r, by Marsaglia's exponential method */
            double xx, yy;
            do {
                xx = -log(gr_uniform(s)) / r;
                yy = -log(gr_uniform(s));
            } while (yy + yy < xx * xx);
            return hz > 0 ? r + xx : -r - xx;
        }
        if (below_exp(gr_zig_f[iz] + gr_uniform(s) * (gr_zig_f[iz - 1] - gr_zig_f[iz]),
                      -0.5 * x * x, iz))
            return x;
        uint64_t u = gr_next64(s);
        iz = (int)(u >> 57);
        hz = (int32_t)(uint32_t)u;
        uint32_t mag = hz < 0 ? (uint32_t)(-hz) : (uint32_t)hz;
        if (mag < gr_zig_k[iz]) return hz * gr_zig_w[iz];
    }
}

/* The batch of rng.h, fast path only: z as gr_normal_batch says when every draw of a
 * stream passes the fast path; seed[j] the state of stream j; returns a mask with bit j
 * set when a draw of stream j does not.  The streams' counters (step0 + j) golden +
 * particle are step0 golden + particle + j golden (mod 2^64); mag is |hz| as gr_normal
 * takes it (2^31 for hz = -2^31).  The mixing loops have no branch and fixed trip
 * counts, so that compilers vectorise them; the look-ups stay scalar here (a compiler
 * gathers them or not by its tuning). */
#if defined(__GNUC__) || defined(__clang__)
#define GR_BATCH_INLINE inline __attribute__((always_inline))
#else
#define GR_BATCH_INLINE inline
#endif

enum { B = GR_NORMAL_BATCH };

static GR_BATCH_INLINE uint32_t batch_fast(uint64_t key, uint64_t step0, uint64_t particle,
                                           int m, double *restrict z, uint64_t *restrict seed,
                                           uint32_t *restrict miss)
{
    uint64_t u[GR_NORMAL_BATCH_MAX_M * B];
    const uint64_t c0 = step0 * GR_GOLDEN + particle;
    for (int j = 0; j < B; j++)
        seed[j] = gr_mix64(key + gr_mix64(c0 + (uint64_t)j * GR_GOLDEN) * GR_GOLDEN);
    for (int k = 0; k < m; k++) {
        const uint64_t inc = (uint64_t)(k + 1) * GR_GOLDEN;
        for (int j = 0; j < B; j++) u[k * B + j] = gr_mix64(seed[j] + inc);
    }
    uint32_t bad = 0;
    for (int k = 0; k < m; k++) {
        uint32_t mk = 0;
        for (int j = 0; j < B; j++) {
            const uint64_t uk = u[k * B + j];
            const int iz = (int)(uk >> 57);
            const int32_t hz = (int32_t)(uint32_t)uk;
            const uint32_t mag = hz < 0 ? 0u - (uint32_t)hz : (uint32_t)hz;
            mk |= (uint32_t)(mag >= gr_zig_k[iz]) << j;
            z[k * B + j] = (double)hz * gr_zig_w[iz];
        }
        miss[k] = mk;
        bad |= mk;
    }
    return bad;
}

typedef uint32_t (*batch_fn)(uint64_t, uint64_t, uint64_t, int, double *restrict,
                             uint64_t *restrict, uint32_t *restrict);

static uint32_t batch_plain(uint64_t key, uint64_t step0, uint64_t particle, int m,
                            double *restrict z, uint64_t *restrict seed,
                            uint32_t *restrict miss)
{
    return batch_fast(key, step0, particle, m, z, seed, miss);
}

/* On x86-64 with GCC >= 6 or Clang (the target attribute, __builtin_cpu_supports and the
 * intrinsics inside a function of another target): the plain loop compiled for AVX2, and
 * the whole batch written out for AVX-512 (8 streams a vector for the 64-bit mixing, the
 * tables held in registers and read by permutes, the fast-path test of all 16 streams one
 * mask), chosen at run time by the CPU's features.
 * Elsewhere only the plain loop exists. */
#if defined(__x86_64__) && (defined(__clang__) || (defined(__GNUC__) && __GNUC__ >= 6))
#define GR_BATCH_X86 1
#include <immintrin.h>

__attribute__((target("avx2"))) static uint32_t batch_avx2(uint64_t key, uint64_t step0,
                                                          uint64_t particle, int m,
                                                          double *restrict z,
                                                          uint64_t *restrict seed,
                                                          uint32_t *restrict miss)
{
    return batch_fast(key, step0, particle, m, z, seed, miss);
}

#define GR_AVX512 __attribute__((target("avx2,avx512f,avx512dq,avx512vl")))

static GR_AVX512 inline __m512i mix8(__m512i z)
{
    z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 30)),
                           _mm512_set1_epi64((long long)0xBF58476D1CE4E5B9ULL));
    z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 27)),
                           _mm512_set1_epi64((long long)0x94D049BB133111EBULL));
    return _mm512_xor_si512(z, _mm512_srli_epi64(z, 31));
}

/* Entry iz (0..127) of a table of 128 x 32 bits held in 8 vectors, for 16 lanes at once:
 * vpermt2d picks from 32 entries (a pair of vectors) by bits 0..4 of each index (the
 * higher bits ignored), b5 and b6 (bits 5 and 6 of iz) choose among the 4 pairs. */
static GR_AVX512 inline __m512i lookup128(const __m512i *t, __m512i iz, __mmask16 b5,
                                          __mmask16 b6)
{
    return _mm512_mask_blend_epi32(
        b6,
        _mm512_mask_blend_epi32(b5, _mm512_permutex2var_epi32(t[0], iz, t[1]),
                                _mm512_permutex2var_epi32(t[2], iz, t[3])),
        _mm512_mask_blend_epi32(b5, _mm512_permutex2var_epi32(t[4], iz, t[5]),
                                _mm512_permutex2var_epi32(t[6], iz, t[7])));
}

/* Why permutes and not gathers: the tables are 512 B (k) and 1 KB (w), 24 vectors, loaded
 * once a call; w is held as its low and its high 32-bit halves, so each of the three
 * look-ups is 4 vpermt2d and 3 blends for 16 draws (and 2 vpermt2d put w's halves back
 * together), against gathers that stall (and against permutes of w as doubles; timings in
 * docs/performance.md). The draw counter is a vector add and z a moving pointer, not
 * (k + 1) golden and z + k B: with -fwrapv (in Python's CFLAGS, which the extension
 * inherits) GCC 12 compiled the indexed form into a slower loop. */
static GR_AVX512 uint32_t batch_avx512(uint64_t key, uint64_t step0, uint64_t particle, int m,
                                       double *restrict z, uint64_t *restrict seed,
                                       uint32_t *restrict miss)
{
    const __m512i golden = _mm512_set1_epi64((long long)GR_GOLDEN);
    const __m512i lane = _mm512_mullo_epi64(_mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0), golden);
    const uint64_t c0 = step0 * GR_GOLDEN + particle;
    /* the low and the high 32 bits of 16 64-bit lanes a, b (a's first), and back */
    const __m512i even =
        _mm512_set_epi32(30, 28, 26, 24, 22, 20, 18, 16, 14, 12, 10, 8, 6, 4, 2, 0);
    const __m512i odd = _mm512_add_epi32(even, _mm512_set1_epi32(1));
    const __m512i join0 =
        _mm512_set_epi32(23, 7, 22, 6, 21, 5, 20, 4, 19, 3, 18, 2, 17, 1, 16, 0);
    const __m512i join1 = _mm512_add_epi32(join0, _mm512_set1_epi32(8));
    /* the tables in registers: kt[q] holds k's entries 16 q .. 16 q + 15, wlo[q] and whi[q]
     * the low and the high halves of w's */
    __m512i kt[8], wlo[8], whi[8];
    for (int q = 0; q < 8; q++) {
        kt[q] = _mm512_loadu_si512((const void *)(gr_zig_k + 16 * q));
        const __m512i a = _mm512_loadu_si512((const void *)(gr_zig_w + 16 * q));
        const __m512i b = _mm512_loadu_si512((const void *)(gr_zig_w + 16 * q + 8));
        wlo[q] = _mm512_permutex2var_epi32(a, even, b);
        whi[q] = _mm512_permutex2var_epi32(a, odd, b);
    }
    /* the 16 streams' seeds, 8 a vector */
    __m512i s0, s1;
    {
        const __m512i c = _mm512_add_epi64(_mm512_set1_epi64((long long)c0), lane);
        s0 = mix8(_mm512_add_epi64(_mm512_set1_epi64((long long)key),
                                   _mm512_mullo_epi64(mix8(c), golden)));
        const __m512i c8 = _mm512_add_epi64(c, _mm512_set1_epi64((long long)(8 * GR_GOLDEN)));
        s1 = mix8(_mm512_add_epi64(_mm512_set1_epi64((long long)key),
                                   _mm512_mullo_epi64(mix8(c8), golden)));
    }
    _mm512_storeu_si512((void *)seed, s0);
    _mm512_storeu_si512((void *)(seed + 8), s1);
    uint32_t bad = 0;
    for (int k = 0; k < m; k++) {
        s0 = _mm512_add_epi64(s0, golden); /* the streams' states at their draw k */
        s1 = _mm512_add_epi64(s1, golden);
        const __m512i u0 = mix8(s0), u1 = mix8(s1);
        /* 16 draws in 32-bit lanes, streams in order: hz the low halves, iz the top 7 bits */
        const __m512i hz = _mm512_permutex2var_epi32(u0, even, u1);
        const __m512i iz = _mm512_srli_epi32(_mm512_permutex2var_epi32(u0, odd, u1), 25);
        const __mmask16 b5 = _mm512_test_epi32_mask(iz, _mm512_set1_epi32(32));
        const __mmask16 b6 = _mm512_test_epi32_mask(iz, _mm512_set1_epi32(64));
        const __m512i mag = _mm512_abs_epi32(hz); /* -2^31 stays 2^31 unsigned */
        const uint32_t mk = _mm512_cmpge_epu32_mask(mag, lookup128(kt, iz, b5, b6));
        miss[k] = mk;
        bad |= mk;
        const __m512i lo = lookup128(wlo, iz, b5, b6), hi = lookup128(whi, iz, b5, b6);
        const __m512d w0 = _mm512_castsi512_pd(_mm512_permutex2var_epi32(lo, join0, hi));
        const __m512d w1 = _mm512_castsi512_pd(_mm512_permutex2var_epi32(lo, join1, hi));
        _mm512_storeu_pd(z, _mm512_mul_pd(_mm512_cvtepi32_pd(_mm512_castsi512_si256(hz)), w0));
        _mm512_storeu_pd(z + 8,
                         _mm512_mul_pd(_mm512_cvtepi32_pd(_mm512_extracti64x4_epi64(hz, 1)), w1));
        z += B;
    }
    return bad;
}
#endif

static batch_fn batch_kernel = batch_plain;
static const char *batch_name = "plain";

/* The widest loop the CPU runs; GRANULAR_RNG_KERNEL=plain or avx2 asks for a narrower one
 * (the tests run each: the bits must not depend on the choice). */
static void pick_batch_kernel(void)
{
#ifdef GR_BATCH_X86
    const char *want = getenv("GRANULAR_RNG_KERNEL");
    __builtin_cpu_init();
    const int avx2 = __builtin_cpu_supports("avx2");
    const int avx512 = avx2 && __builtin_cpu_supports("avx512f") &&
                       __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl");
    if (want && strcmp(want, "plain") == 0) return;
    if (avx512 && !(want && strcmp(want, "avx2") == 0)) {
        batch_kernel = batch_avx512;
        batch_name = "avx512";
    } else if (avx2) {
        batch_kernel = batch_avx2;
        batch_name = "avx2";
    }
#endif
}

const char *gr_normal_batch_kernel(void)
{
    return batch_name;
}

/* The index of the lowest set bit of x != 0. */
static inline int lowest_bit(uint32_t x)
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctz(x);
#else
    int j = 0;
    while (!(x >> j & 1)) j++;
    return j;
#endif
}

void gr_normal_batch(uint64_t key, uint64_t step0, uint64_t particle, int m, double *z)
{
    uint64_t seed[B];
    uint32_t miss[GR_NORMAL_BATCH_MAX_M];
    const uint32_t bad = batch_kernel(key, step0, particle, m, z, seed, miss);
    if (!bad) return;
    /* A stream whose draw k0 misses the fast path: its draws before k0 are right; from
     * k0 on, gr_normal's own sequence -- the slow path of draw k0 with the stream where
     * gr_normal leaves it (k0 + 1 draws in), then the draws after it, shifted by however
     * many the slow path took. */
    for (uint32_t left = bad; left; left &= left - 1) {
        const int j = lowest_bit(left);
        int k = 0;
        while (!(miss[k] >> j & 1)) k++;
        gr_stream s = {seed[j] + (uint64_t)(k + 1) * GR_GOLDEN};
        const uint64_t u = gr_mix64(s.state);
        z[k * B + j] = gr_normal_tail(&s, (int32_t)(uint32_t)u, (int)(u >> 57));
        for (k++; k < m; k++) z[k * B + j] = gr_normal(&s);
    }
}
