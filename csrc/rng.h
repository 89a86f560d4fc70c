/* rng.h -- counter-based random numbers: every draw is a pure function of
 * (key, step, particle, k), so results never depend on how the work is split into
 * chunks or threads.
 *
 * Generator: a SplitMix64 stream per (step, particle).  Its seed is the 64-bit finaliser
 * of SplitMix64 (Stafford's "Mix13") applied to key + counter * golden-gamma, and draw k
 * of the stream is the finaliser of seed + (k + 1) * gamma -- the construction of
 * SplitMix64 itself, which passes BigCrush.  Normal variates: the ziggurat method of
 * Marsaglia and Tsang (2000) with 128 layers, taking the layer from the high bits and
 * the magnitude from the low 32 bits of one 64-bit draw so the two are independent. */
#ifndef GR_RNG_H
#define GR_RNG_H

#include <math.h>
#include <stdint.h>

#define GR_GOLDEN 0x9E3779B97F4A7C15ULL

static inline uint64_t gr_mix64(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

typedef struct {
    uint64_t state;
} gr_stream;

/* The stream of draws for one (step, particle) under a key. */
static inline gr_stream gr_stream_at(uint64_t key, uint64_t step, uint64_t particle)
{
    gr_stream s;
    s.state = gr_mix64(key + gr_mix64(step * GR_GOLDEN + particle) * GR_GOLDEN);
    return s;
}

static inline uint64_t gr_next64(gr_stream *s)
{
    s->state += GR_GOLDEN;
    return gr_mix64(s->state);
}

/* Uniform in (0, 1), never 0 or 1 (53 bits). */
static inline double gr_uniform(gr_stream *s)
{
    return ((double)(gr_next64(s) >> 11) + 0.5) * (1.0 / 9007199254740992.0);
}

/* Ziggurat tables, filled once by gr_rng_init() (call it before the first draw, from
 * one thread; later calls return at once). */
extern int gr_rng_ready;
extern uint32_t gr_zig_k[128];
extern double gr_zig_w[128], gr_zig_f[128];
void gr_rng_init(void);
/* The slow path of gr_normal: the tail, the wedges (their test calls exp only when a
 * bracket of it cannot decide, with the same answer -- rng.c) and the redraws. */
double gr_normal_tail(gr_stream *s, int64_t hz, int iz);

/* A standard normal variate. */
static inline double gr_normal(gr_stream *s)
{
    uint64_t u = gr_next64(s);
    int iz = (int)(u >> 57);            /* layer: top 7 bits */
    int32_t hz = (int32_t)(uint32_t)u;  /* signed magnitude: low 32 bits */
    uint32_t mag = hz < 0 ? (uint32_t)(-(int64_t)hz) : (uint32_t)hz;
    if (mag < gr_zig_k[iz]) return hz * gr_zig_w[iz];
    return gr_normal_tail(s, hz, iz);
}

/* Normals for a batch of consecutive streams, the same bits as gr_normal.
 *
 * The steps of one particle are a chain only through its state; their random numbers are
 * independent functions of the step.  So the engine (sde.c) draws them ahead,
 * GR_NORMAL_BATCH steps at a time: gr_normal_batch(key, step0, particle, m, z) sets
 * z[k * GR_NORMAL_BATCH + j] to the k-th of m normals that gr_normal draws in turn from
 * gr_stream_at(key, step0 + j, particle), for j < GR_NORMAL_BATCH and k < m <=
 * GR_NORMAL_BATCH_MAX_M.
 *
 * How, and why the bits are the same: every draw of the batch is first taken as if it
 * and the draws before it passed the ziggurat's fast path -- then the k-th draw of a
 * stream is gr_mix64(seed + (k + 1) golden), a pure function of (stream seed, k) -- in
 * loops with no branch and fixed trip counts that vectorise (64-bit integer arithmetic,
 * two table look-ups, one int-to-double conversion and one multiplication, each exact or
 * correctly rounded the same way in any instruction set).  A draw that misses the fast
 * path (2.8% of draws: the wedges, the tail, and layer 1, whose k is 0) is redone by
 * gr_normal's own slow path from the stream state gr_normal would have there, and the
 * stream's later draws by gr_normal (the slow path draws more, shifting them).  On x86-64
 * with GCC or Clang the batch exists plain, compiled for AVX2, and written for AVX-512
 * with intrinsics (16 streams at once, the tables held in registers); gr_rng_init picks
 * the widest the CPU runs (rng.c).  Only integer work and that lone multiply happen there, and the
 * particle update stays in portable code: nothing can be fused or reordered. */
#define GR_NORMAL_BATCH 16
#define GR_NORMAL_BATCH_MAX_M 6
void gr_normal_batch(uint64_t key, uint64_t step0, uint64_t particle, int m, double *z);
/* The batch loop in use: "plain", "avx2" or "avx512" (set by gr_rng_init). */
const char *gr_normal_batch_kernel(void);

#endif
