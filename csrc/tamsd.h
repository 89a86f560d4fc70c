/* tamsd.h -- which windows the SDE engine's time-averaged MSD averages, and the plan that
 * books them while a particle is stepped (csrc/sde.c).
 *
 * For a lag of k steps, the TAMSD of a particle is the mean over windows [t0, t0 + k] of
 * |x(t0 + k) - x(t0)|^2, the windows starting at every multiple of a stride s:
 *
 *   "all"     (GR_TAMSD_ALL):     s = 1, every window of the run;
 *   "strided" (GR_TAMSD_STRIDED): s = the largest power of two <= max(1, k / W), W =
 *             GR_TAMSD_OVERLAP, so that W to 2W windows overlap any one (s = 1 below
 *             lag 2W: every window).
 *
 * Cost.  The engine books a window where it ends, reading the start position from a
 * ring; a lag of stride s books 1/s windows a step, so the strided estimator costs about
 * sum_k min(1, 2 W / k) window reads a step -- the short lags (< 2W) one each, the others
 * 2W/k at most, a sum that converges for log-spaced lags however many of them there are
 * (their share falls as 1/k).  Start positions are kept per *level* e (stride 2^e), not
 * per lag: a level stores the position at every multiple of 2^e in a ring of
 * GR_TAMSD_LEVEL_LEN, shared by all the lags of that stride, so stores cost at most
 * sum_e 2^-e < 2 a step whatever the lags.  Which lags end a window at a step repeats
 * with the largest stride, so a table over the phases of one period lists them (the
 * "phase table"; strides past GR_TAMSD_MAX_PHASES go to a short list of slow lags
 * checked only when one of them is due): no step scans the lags that are not due.
 *
 * Statistical error.  For Brownian increments (an overdamped or long-lag walk with
 * stationary increments) and windows overlapping by W = k / s, the relative variance of
 * one particle's TAMSD over a run of T steps is, for k << T,
 *     Var / mean^2 = (2 k / (d T)) (2 + 1/W^2) / 3
 * (sum of squared overlaps of the windows: Cov(dx_i^2, dx_j^2) = 2 Cov(dx_i, dx_j)^2
 * per axis for Gaussian increments).  Every window (W = k) gives 4k/(3dT), the
 * ergodicity-breaking parameter of Brownian motion (Deng & Barkai, Phys. Rev. E 79,
 * 011112 (2009): EB = k(H) lag/T with k(1/2) = 4/3, in 1D).  So the strided estimator's
 * variance is (2 + 1/W^2) / (2 + 1/k^2) that of "all": 1.031 at most for W = 4 (std
 * +1.5%), 1 for lags < 2W, which use every window.  tests/test_langevin.py measures the
 * ratio.  Where it stops: the formula takes increments independent beyond the lag (lag
 * >> 1/gamma); at shorter lags the velocity correlates windows over 1/gamma > lag, which
 * strides of lag/4 to lag/8 sample far more finely than that time. */
#ifndef GR_TAMSD_H
#define GR_TAMSD_H

#include <stdint.h>

enum { GR_TAMSD_STRIDED = 0, GR_TAMSD_ALL = 1 };

#define GR_TAMSD_OVERLAP 4                         /* W: windows overlapping any one */
#define GR_TAMSD_LEVEL_LEN (4 * GR_TAMSD_OVERLAP)  /* a level's ring: > 2W positions */
#define GR_TAMSD_MAX_PHASE_BITS 12                 /* phase table of at most 4096 steps */
/* The every-window estimator's ring holds max lag + 1 positions: refuse lags past this */
#define GR_TAMSD_ALL_MAX_LAG ((int64_t)1 << 30)

/* log2 of the stride of a lag (>= 1) under an estimator. */
int gr_tamsd_level(int64_t lag, int estimator);
/* The stride: 2^gr_tamsd_level. */
int64_t gr_tamsd_stride(int64_t lag, int estimator);
/* Doubles of ring (one particle's stored positions) for the lags (each >= 1), or -1 if
 * that overflows or an "all" lag exceeds GR_TAMSD_ALL_MAX_LAG. */
int64_t gr_tamsd_ring_size(int dim, int64_t n_lags, const int64_t *lags, int estimator);

/* The bookkeeping of a set of lags, the same for every particle: built once per call,
 * read by every thread. */
/* What a window end of one lag reads: the lag, its stride 2^level, and its level's ring. */
typedef struct {
    int64_t lag, off, mask; /* ring offset (doubles) and length - 1 */
    int64_t level;
} gr_tamsd_lag;

typedef struct {
    int64_t n_lags;
    const int64_t *lags;        /* increasing, >= 1 */
    gr_tamsd_lag *lag;          /* per lag */
    int64_t n_every;            /* lags 0 .. n_every-1 have stride 1 (a prefix: strides
                                   grow with the lag): booked at every step, not listed
                                   in the phase table */
    int64_t phase_mask;         /* the phase table's period - 1 (a power of two; the
                                   largest stride from 2 to 2^GR_TAMSD_MAX_PHASE_BITS) */
    int64_t *phase_off;         /* period + 1: phase p's lags are phase_lag[off[p]..off[p+1]) */
    int64_t *phase_lag;         /* lags (indices) ending a window at steps of each phase */
    int64_t *gap;               /* per phase: steps to the next phase with any bookkeeping */
    int64_t n_slow;             /* lags whose stride exceeds the period */
    int64_t *slow;              /* their indices */
    int top;                    /* highest level in use */
    uint64_t used;              /* bit e: level e in use */
    int64_t level_off[64];      /* per level: ring offset (doubles) */
    int64_t level_mask[64];     /* per level: ring length - 1 */
} gr_tamsd_plan;

/* Build the plan (lags checked by the caller: increasing, >= 1, ring size >= 0).
 * Returns GR_OK or GR_ERR_NOMEM (nothing to free then). */
int gr_tamsd_plan_init(gr_tamsd_plan *p, int dim, int64_t n_lags, const int64_t *lags,
                       int estimator);
void gr_tamsd_plan_free(gr_tamsd_plan *p);

#endif
