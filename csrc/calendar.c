/* calendar.c -- indexed calendar queue; see calendar.h for the idea and the invariants. */
#define _DEFAULT_SOURCE         /* madvise (hugemem.h) */
#define _POSIX_C_SOURCE 200112L /* posix_memalign */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "calendar.h"
#include "common.h"
#include "hugemem.h"

/* an item's prev: the head of a list, in the near heap, in no structure (calendar.h) */
enum { GR_CQ_HEAD = -1, GR_CQ_NEAR = -2, GR_CQ_NONE = -3 };

/* Keys per bucket the width aims at: the near heap then stays a few entries deep, and
 * few buckets are stepped over empty.  Measured best among 1, 2, 4, 8 (edmd_perf.py). */
#define GR_CQ_PER_BUCKET 2.0
/* Bucket slots per id.  The calendar covers nb buckets ahead of the start of the
 * current "year" (over_from - nb), so on average half of that ahead of now; keys
 * further ahead take the slower way through the overflow list.  That fraction is about
 * (mean time to a key) / (nb w) ~ n / (GR_CQ_PER_BUCKET nb): 4 slots per id keep it
 * near 1/8 for 16 bytes per id. */
#define GR_CQ_SLOTS_PER_ID 4
/* Key changes per id between rebuilds, at first (see rebuild()). */
#define GR_CQ_REBUILD 4
/* Far keys (all keys left being in the overflow list) above which the next one is found
 * by a rebuild rather than by a walk over the list. */
#define GR_CQ_FEW_FAR 64
/* Keys sampled to estimate their spread when choosing the width. */
#define GR_CQ_SAMPLE 1024

/* Monotonic non-decreasing in t, which is all the ordering needs; truncation rather
 * than floor (keys before t0 share bucket 0, harmlessly). */
static inline int64_t bucket_of(const gr_cq *q, double t)
{
    double x = (t - q->t0) * q->inv_w;
    if (!(x < GR_CQ_FAR)) return (int64_t)GR_CQ_FAR;
    if (x < -GR_CQ_FAR) return -(int64_t)GR_CQ_FAR;
    return (int64_t)x;
}

/* ---- the near heap: a binary min-heap of (key, id), item[id].next = its slot (and
 * item[id].prev = GR_CQ_NEAR, set where an id enters the heap) ---- */

static inline void near_place(gr_cq *q, int32_t k, gr_cq_near e)
{
    q->near[k] = e;
    q->item[e.id].next = k;
}

static void near_sift_up(gr_cq *q, int32_t k, gr_cq_near e)
{
    while (k > 0) {
        int32_t parent = (k - 1) >> 1;
        if (!(e.t < q->near[parent].t)) break;
        near_place(q, k, q->near[parent]);
        k = parent;
    }
    near_place(q, k, e);
}

static void near_sift_down(gr_cq *q, int32_t k, gr_cq_near e)
{
    const int32_t n = q->n_near;
    for (;;) {
        int32_t c = 2 * k + 1;
        if (c >= n) break;
        if (c + 1 < n && q->near[c + 1].t < q->near[c].t) c++;
        if (!(q->near[c].t < e.t)) break;
        near_place(q, k, q->near[c]);
        k = c;
    }
    near_place(q, k, e);
}

static void near_remove(gr_cq *q, int32_t k)
{
    gr_cq_near last = q->near[--q->n_near];
    if (k == q->n_near) return;
    if (k > 0 && last.t < q->near[(k - 1) >> 1].t) near_sift_up(q, k, last);
    else near_sift_down(q, k, last);
}

/* ---- lists ---- */

static inline void list_push(gr_cq *q, int32_t *head, int32_t id)
{
    gr_cq_item *it = &q->item[id];
    it->prev = GR_CQ_HEAD;
    it->next = *head;
    if (*head >= 0) q->item[*head].prev = id;
    *head = id;
}

static inline void list_unlink(gr_cq *q, int32_t *head, int32_t id)
{
    gr_cq_item *it = &q->item[id];
    if (it->prev >= 0) q->item[it->prev].next = it->next;
    else *head = it->next;
    if (it->next >= 0) q->item[it->next].prev = it->prev;
}

/* Put id (finite key, in no structure) where the invariant wants it. */
static inline void place(gr_cq *q, int32_t id)
{
    double t = q->item[id].t;
    int64_t b = bucket_of(q, t);
    if (b <= q->cur) {
        gr_cq_near e = {t, id};
        q->item[id].prev = GR_CQ_NEAR;
        near_sift_up(q, q->n_near++, e);
    } else if (b < q->over_from) {
        list_push(q, &q->head[b & (q->nb - 1)], id);
        q->n_list++;
    } else {
        list_push(q, &q->over, id);
        q->n_over++;
    }
}

static inline void take_out(gr_cq *q, int32_t id)
{
    gr_cq_item *it = &q->item[id];
    if (it->prev == GR_CQ_NEAR) {
        near_remove(q, it->next);
    } else if (it->prev != GR_CQ_NONE) { /* a list: which one, its key says */
        const int64_t b = bucket_of(q, it->t);
        if (b < q->over_from) {
            list_unlink(q, &q->head[b & (q->nb - 1)], id);
            q->n_list--;
        } else {
            list_unlink(q, &q->over, id);
            q->n_over--;
        }
    } else if (q->nan_id == id) {
        q->nan_id = -1;
    }
    it->prev = GR_CQ_NONE;
}

/* Move the overflow keys that now fall before over_from into the calendar. */
static void spill(gr_cq *q)
{
    for (int32_t id = q->over, nx; id >= 0; id = nx) {
        nx = q->item[id].next;
        if (bucket_of(q, q->item[id].t) < q->over_from) {
            list_unlink(q, &q->over, id);
            q->n_over--;
            place(q, id);
        }
    }
}

/* The k-th smallest of x[0 .. m-1] (k < m), reordering x: Hoare's selection, O(m) on
 * average.  A full sort of the sample cost more than the rest of a rebuild at small N. */
static double select_kth(double *x, int m, int k)
{
    int lo = 0, hi = m - 1;
    while (lo < hi) {
        double pivot = x[lo + (hi - lo) / 2];
        int a = lo, b = hi;
        while (a <= b) {
            while (x[a] < pivot) a++;
            while (pivot < x[b]) b--;
            if (a <= b) {
                double t = x[a];
                x[a++] = x[b];
                x[b--] = t;
            }
        }
        if (k <= b) hi = b;
        else if (k >= a) lo = a;
        else break; /* b < k < a: x[k] equals the pivot */
    }
    return x[k];
}

/* Start the calendar afresh at the smallest key, with a width from the keys' spread:
 * if the median of (key - smallest) over an evenly strided sample is m, about half of
 * the nf finite keys lie within m, so the keys are about 2 m / nf apart. */
static void rebuild(gr_cq *q)
{
    const int32_t n = q->n;
    double tmin = INFINITY;
    int32_t nf = 0;
    for (int32_t id = 0; id < n; id++) {
        double t = q->item[id].t;
        if (isfinite(t)) {
            nf++;
            if (t < tmin) tmin = t;
        }
    }
    double w = 0.0;
    q->t0 = nf > 0 ? tmin : 0.0;
    if (nf > 1) {
        double sample[GR_CQ_SAMPLE];
        int m = 0;
        int32_t stride = n / GR_CQ_SAMPLE > 1 ? n / GR_CQ_SAMPLE : 1;
        for (int32_t id = 0; id < n && m < GR_CQ_SAMPLE; id += stride)
            if (isfinite(q->item[id].t)) sample[m++] = q->item[id].t - tmin;
        if (m > 0) {
            double median = select_kth(sample, m, m / 2), largest = sample[0];
            for (int k = 1; k < m; k++) largest = sample[k] > largest ? sample[k] : largest;
            double spread = median > 0.0 ? 2.0 * median : largest;
            w = GR_CQ_PER_BUCKET * spread / nf;
        }
    }
    const double inv_w_before = q->inv_w;
    q->inv_w = 1.0 / w;
    if (!(w > 0.0) || !isfinite(q->inv_w)) q->inv_w = 1.0; /* all keys equal: any width */
    memset(q->head, 0xff, (size_t)q->nb * sizeof *q->head); /* every byte 0xff: -1 */
    q->over = -1;
    q->n_list = q->n_over = 0;
    q->n_near = 0;
    q->nan_id = -1;
    q->cur = 0;
    q->over_from = q->nb;
    for (int32_t id = 0; id < n; id++) {
        double t = q->item[id].t;
        q->item[id].prev = GR_CQ_NONE;
        if (t != t) q->nan_id = id;
        else if (t != INFINITY) place(q, id);
    }
    q->changes = 0;
    /* No keys yet: rebuild once the caller has set them.  Else after GR_CQ_REBUILD n key
     * changes; while the width comes out within 20 % of the last one (a gas in a steady
     * state) the interval doubles, up to 16 times that, and it starts again at the first
     * width that has moved (a gas that cools or heats is rebuilt as often as before).  A
     * rebuild reads every key and, at large N, misses on most of them. */
    const int64_t first = GR_CQ_REBUILD * (int64_t)n + 64;
    const double moved = q->inv_w / inv_w_before;
    if (nf == 0) q->rebuild_at = 0;
    else if (q->rebuild_at >= first && moved > 1.0 / 1.2 && moved < 1.2)
        q->rebuild_at = q->rebuild_at < 8 * first ? 2 * q->rebuild_at : 16 * first;
    else q->rebuild_at = first;
}

int gr_cq_init(gr_cq *q, int32_t n)
{
    q->n = n;
    q->depth = 1;
    q->inv_w = 1.0;     /* rebuild() compares the width it finds with these */
    q->rebuild_at = 0;
    q->nb = 16;
    while (q->nb < GR_CQ_SLOTS_PER_ID * (int64_t)n && q->nb < (1 << 30)) q->nb <<= 1;
    q->item = gr_big_alloc((size_t)n * sizeof *q->item);
    q->head = gr_big_alloc((size_t)q->nb * sizeof *q->head);
    q->near = malloc((size_t)(n > 0 ? n : 1) * sizeof *q->near);
    if (!q->item || !q->head || !q->near) {
        gr_cq_free(q);
        return GR_ERR_NOMEM;
    }
    for (int32_t id = 0; id < n; id++) q->item[id].t = INFINITY;
    rebuild(q);
    return GR_OK;
}

void gr_cq_free(gr_cq *q)
{
    free(q->item);
    free(q->head);
    free(q->near);
    q->item = NULL;
    q->head = NULL;
    q->near = NULL;
}

void gr_cq_update(gr_cq *q, int32_t id, double t)
{
    take_out(q, id);
    q->item[id].t = t;
    q->changes++;
    if (t != t) q->nan_id = id;
    else if (t != INFINITY) place(q, id);
}

int32_t gr_cq_top_slow(gr_cq *q, double *t)
{
    if (q->nan_id >= 0) {
        *t = NAN;
        return q->nan_id;
    }
    if (q->changes >= q->rebuild_at) rebuild(q);
    while (q->n_near < q->depth) {
        if (q->n_list == 0) {
            if (q->n_near > 0) break;
            if (q->n_over == 0) {
                *t = INFINITY;
                return -1;
            }
            /* Only far keys left.  Many of them: the width is wrong for them (it was
             * taken from keys bunched near one instant, say a lattice start whose first
             * events are all face crossings at t ~ 0), and finding the first by a walk
             * over the overflow list at every event would cost O(n) each.  A rebuild
             * reads the same keys once and gives them a width from their own spread. */
            if (q->n_over > GR_CQ_FEW_FAR) {
                rebuild(q);
                continue;
            }
            /* a few: jump to the first of them rather than step there */
            int64_t bmin = (int64_t)GR_CQ_FAR;
            for (int32_t id = q->over; id >= 0; id = q->item[id].next) {
                int64_t b = bucket_of(q, q->item[id].t);
                if (b < bmin) bmin = b;
            }
            q->cur = bmin;
            q->over_from = (bmin / q->nb + 1) * q->nb;
            spill(q);
            continue;
        }
        q->cur++;
        if (q->cur >= q->over_from) {
            q->over_from += q->nb;
            spill(q);
        }
        int32_t *head = &q->head[q->cur & (q->nb - 1)];
        if (q->depth > 1) {
            /* Where the caller prefetches events ahead (large N), draining a bucket was a
             * chain of misses: its slot, then each key's item.  The next buckets are asked
             * for in stages, each reading what the stage before asked for a drain ago (a
             * drain every few events): the slot three buckets on, the first item two on,
             * the item after that one on.  Written out here, not in a helper: GCC deletes
             * calls to a function that only prefetches (see edmd.c). */
            const int32_t mask = q->nb - 1;
            GR_CQ_PREFETCH_HEAD(q, (q->cur + 3) & mask);
            const int32_t first2 = q->head[(q->cur + 2) & mask];
            if (first2 >= 0) GR_CQ_PREFETCH(q, first2);
            const int32_t first1 = q->head[(q->cur + 1) & mask];
            if (first1 >= 0 && q->item[first1].next >= 0) GR_CQ_PREFETCH(q, q->item[first1].next);
        }
        while (*head >= 0) {
            int32_t id = *head;
            *head = q->item[id].next;
            q->n_list--;
            gr_cq_near e = {q->item[id].t, id};
            q->item[id].prev = GR_CQ_NEAR;
            near_sift_up(q, q->n_near++, e);
        }
    }
    *t = q->near[0].t;
    return q->near[0].id;
}

void gr_cq_renumber(gr_cq *q, const int32_t *newpos)
{
    /* permute the keys in place, cycle by cycle, with `prev` marking the ids done
     * (rebuild() sets every `prev` afresh); no allocation, so nothing can fail */
    gr_cq_item *it = q->item;
    for (int32_t id = 0; id < q->n; id++) it[id].prev = 0;
    for (int32_t start = 0; start < q->n; start++) {
        if (it[start].prev) continue;
        double carry = it[start].t;
        int32_t j = start;
        do {
            int32_t k = newpos[j];
            double t = it[k].t;
            it[k].t = carry;
            it[k].prev = 1;
            carry = t;
            j = k;
        } while (j != start);
    }
    rebuild(q);
}

/* Walk the list from head (ids with keys in buckets [blo, bhi) and, for a bucket slot
 * >= 0, in that slot), marking ids seen.  Adds the ids walked to *count; returns NULL or
 * the fault. */
static const char *check_list(const gr_cq *q, int32_t head, int64_t blo, int64_t bhi,
                              int64_t slot, uint8_t *seen, int64_t *count)
{
    int32_t prev = GR_CQ_HEAD;
    for (int32_t id = head; id != -1; id = q->item[id].next) {
        if (id < 0 || id >= q->n) return "a queue list links to an id out of range";
        if (seen[id]) return "a queue id is in two places, or a list has a cycle";
        seen[id] = 1;
        const gr_cq_item *it = &q->item[id];
        if (it->prev != prev) return "a queue list's links are inconsistent";
        if (!(it->t == it->t) || it->t == INFINITY) return "a queue list holds a key of +inf or NaN";
        const int64_t b = bucket_of(q, it->t);
        if (b < blo || b >= bhi || (slot >= 0 && (b & (q->nb - 1)) != slot))
            return "a queue key sits in the wrong bucket";
        if (++*count > q->n) return "a queue list is longer than the ids";
        prev = id;
    }
    return NULL;
}

const char *gr_cq_check(const gr_cq *q, uint8_t *seen)
{
    const int32_t n = q->n;
    if (q->nb < 16 || (q->nb & (q->nb - 1)) != 0) return "the queue's slot count is not a power of two";
    if (q->n_near < 0 || q->n_near > n || q->n_list < 0 || q->n_list > n || q->n_over < 0 ||
        q->n_over > n || q->n_near + q->n_list + q->n_over > n)
        return "the queue's counts are out of range";
    if (q->nan_id < -1 || q->nan_id >= n || q->over < -1 || q->over >= n)
        return "a queue id is out of range";
    if (!(q->inv_w > 0.0) || !isfinite(q->inv_w) || q->t0 != q->t0)
        return "the queue's bucket width or start is not a positive finite number";
    /* bucket numbers are saturated at 2^62, and the calendar spans at most nb of them */
    const int64_t far = (int64_t)GR_CQ_FAR;
    if (q->cur < -far || q->cur > far || q->over_from <= q->cur || q->nb < 0 ||
        q->over_from > q->cur + q->nb) /* cur is bounded: the sum cannot overflow */
        return "the queue's current bucket and overflow start are inconsistent";
    for (int32_t k = 0; k < q->n_near; k++) {
        const gr_cq_near e = q->near[k];
        if (e.id < 0 || e.id >= n) return "the queue's near heap holds an id out of range";
        if (seen[e.id]) return "a queue id is twice in the near heap";
        seen[e.id] = 1;
        const gr_cq_item *it = &q->item[e.id];
        if (it->prev != GR_CQ_NEAR || it->next != k || memcmp(&it->t, &e.t, sizeof e.t) != 0)
            return "the queue's near heap disagrees with its items";
        if (!(e.t == e.t) || e.t == INFINITY || bucket_of(q, e.t) > q->cur)
            return "the queue's near heap holds a key that belongs elsewhere";
        if (k > 0 && e.t < q->near[(k - 1) >> 1].t) return "the queue's near heap is not ordered";
    }
    int64_t listed = 0, over = 0;
    for (int32_t slot = 0; slot < q->nb; slot++) {
        const char *fault =
            check_list(q, q->head[slot], q->cur + 1, q->over_from, slot, seen, &listed);
        if (fault) return fault;
    }
    if (listed != q->n_list) return "the queue's bucket lists do not hold n_list ids";
    const char *fault = check_list(q, q->over, q->over_from, INT64_MAX, -1, seen, &over);
    if (fault) return fault;
    if (over != q->n_over) return "the queue's overflow list does not hold n_over ids";
    for (int32_t id = 0; id < n; id++) {
        if (seen[id]) continue;
        const gr_cq_item *it = &q->item[id];
        if (it->prev != GR_CQ_NONE) return "a queue id is marked as placed but is in no list";
        if (it->t != INFINITY && !(it->t != it->t && id == q->nan_id))
            return "a queue id with an event time is in no list";
    }
    if (q->nan_id >= 0 && (seen[q->nan_id] || q->item[q->nan_id].t == q->item[q->nan_id].t))
        return "the queue's NaN id has no NaN key";
    return NULL;
}
