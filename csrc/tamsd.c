/* tamsd.c -- the TAMSD windows' strides, ring layout and phase table (see tamsd.h). */
#include <stdlib.h>
#include <string.h>

#include "common.h"
#include "tamsd.h"

int gr_tamsd_level(int64_t lag, int estimator)
{
    if (estimator == GR_TAMSD_ALL) return 0;
    int64_t w = lag / GR_TAMSD_OVERLAP; /* the stride is the largest 2^e <= max(1, w) */
    int e = 0;
    while (w >= 2) {
        w >>= 1;
        e++;
    }
    return e;
}

int64_t gr_tamsd_stride(int64_t lag, int estimator)
{
    return (int64_t)1 << gr_tamsd_level(lag, estimator);
}

/* Ring length of level e for the lags (0 when unused): a stored start is read at most
 * ceil(lag / 2^e) <= 2W stores later (lag < 2W 2^e), so 4W positions; every window of
 * "all" needs the last lag + 1 positions, rounded up to a power of two. */
static int64_t level_len(int e, int64_t n_lags, const int64_t *lags, int estimator)
{
    int used = 0;
    for (int64_t l = 0; l < n_lags; l++) used |= gr_tamsd_level(lags[l], estimator) == e;
    if (!used) return 0;
    if (estimator != GR_TAMSD_ALL) return GR_TAMSD_LEVEL_LEN;
    const int64_t need = lags[n_lags - 1] + 1; /* lags increase */
    int64_t len = 1;
    while (len < need) len <<= 1;
    return len;
}

int64_t gr_tamsd_ring_size(int dim, int64_t n_lags, const int64_t *lags, int estimator)
{
    if (n_lags == 0) return 0;
    if (estimator == GR_TAMSD_ALL && lags[n_lags - 1] > GR_TAMSD_ALL_MAX_LAG) return -1;
    int64_t total = 0;
    for (int e = 0; e < 63; e++) total += level_len(e, n_lags, lags, estimator) * dim;
    return total; /* <= 63 x 16 x 3, or 2^31 x 3 */
}

void gr_tamsd_plan_free(gr_tamsd_plan *p)
{
    free(p->lag);
    free(p->phase_off), free(p->phase_lag), free(p->gap), free(p->slow);
    memset(p, 0, sizeof *p);
}

int gr_tamsd_plan_init(gr_tamsd_plan *p, int dim, int64_t n_lags, const int64_t *lags,
                       int estimator)
{
    memset(p, 0, sizeof *p);
    p->n_lags = n_lags;
    p->lags = lags;
    p->top = -1;
    int64_t off = 0;
    for (int e = 0; e < 63; e++) {
        const int64_t len = level_len(e, n_lags, lags, estimator);
        p->level_off[e] = off;
        p->level_mask[e] = len ? len - 1 : 0;
        if (len) {
            p->used |= (uint64_t)1 << e;
            p->top = e;
        }
        off += len * dim;
    }
    /* the period: the largest stride up to 2^GR_TAMSD_MAX_PHASE_BITS (1 if none > 1) */
    int q = 0;
    for (int64_t l = 0; l < n_lags; l++) {
        const int e = gr_tamsd_level(lags[l], estimator);
        if (e <= GR_TAMSD_MAX_PHASE_BITS && e > q) q = e;
    }
    const int64_t period = (int64_t)1 << q;
    p->phase_mask = period - 1;
    const size_t nl = (size_t)n_lags + 1; /* + 1: never 0 bytes */
    p->lag = malloc(nl * sizeof(gr_tamsd_lag));
    p->slow = malloc(nl * sizeof(int64_t));
    p->phase_off = calloc((size_t)period + 1, sizeof(int64_t));
    p->gap = malloc((size_t)period * sizeof(int64_t));
    if (!p->lag || !p->slow || !p->phase_off || !p->gap) goto nomem;
    /* count the table's entries per phase: lag k (stride s <= period) ends a window at
     * the steps k + j s, i.e. at the phases = k (mod s) */
    for (int64_t l = 0; l < n_lags; l++) {
        const int e = gr_tamsd_level(lags[l], estimator);
        p->lag[l] = (gr_tamsd_lag){lags[l], p->level_off[e], p->level_mask[e], e};
        if (e == 0) {
            p->n_every = l + 1;
            continue;
        }
        if (e > q) {
            p->slow[p->n_slow++] = l;
            continue;
        }
        const int64_t s = (int64_t)1 << e;
        for (int64_t ph = lags[l] & (s - 1); ph < period; ph += s) p->phase_off[ph + 1]++;
    }
    for (int64_t ph = 0; ph < period; ph++) p->phase_off[ph + 1] += p->phase_off[ph];
    p->phase_lag = malloc(((size_t)p->phase_off[period] + 1) * sizeof(int64_t));
    if (!p->phase_lag) goto nomem;
    {
        int64_t *fill = p->gap; /* as scratch: the next free entry per phase */
        memcpy(fill, p->phase_off, (size_t)period * sizeof(int64_t));
        for (int64_t l = p->n_every; l < n_lags; l++) {
            const int e = (int)p->lag[l].level;
            if (e > q) continue;
            const int64_t s = (int64_t)1 << e;
            for (int64_t ph = lags[l] & (s - 1); ph < period; ph += s) p->phase_lag[fill[ph]++] = l;
        }
    }
    /* a phase is busy if a window ends there or a level stores (level e at multiples of
     * 2^e; levels above the period at multiples of it, phase 0); gap: steps from a phase
     * to the next busy one, cyclically (phase 0 is busy whenever there are lags) */
    for (int64_t ph = period - 1, next = period; ph >= 0; ph--) {
        int busy = p->phase_off[ph + 1] > p->phase_off[ph] || (ph == 0 && n_lags > 0) ||
                   p->n_every > 0;
        for (int e = 0; e <= q && !busy; e++)
            busy = (p->used >> e & 1) && (ph & (((int64_t)1 << e) - 1)) == 0;
        if (busy) next = ph;
        p->gap[ph] = next - ph; /* next = period: phase 0 of the next period */
    }
    return GR_OK;
nomem:
    gr_tamsd_plan_free(p);
    return GR_ERR_NOMEM;
}
