/* calendar.h -- an indexed calendar queue of event times, one key per id.
 *
 * The queue knows no physics: it maps an id to one key (the time of that id's next
 * event, +inf for none) and answers "which id has the smallest key".  An indexed binary
 * or 4-ary heap does this in O(log N) per change, and at large N every level of a sift
 * is a cache miss.  Here time is cut into buckets of width w: keys in the current bucket
 * sit in a small binary heap (the "near" heap, a handful of entries), keys in the next
 * nb - 1 buckets or so sit in one doubly linked list per bucket, and keys further ahead
 * in one overflow list.  A change of key is an unlink and a push, O(1); the near heap is
 * refilled from the next bucket when it runs empty.  w is chosen from the spread of the
 * keys whenever the queue is rebuilt (so that a bucket holds a few keys), and the queue
 * rebuilds itself every 4 N key changes (up to 64 N while the width holds), so it follows
 * a system that cools or heats.
 *
 * Invariants (cur = the current bucket number, over_from = the first bucket number of
 * the overflow, cur < over_from <= cur + nb, bucket(t) = floor((t - t0) / w)):
 *  - every id with a finite key is in exactly one place: the near heap iff
 *    bucket(key) <= cur; the list of slot bucket(key) mod nb iff cur < bucket(key) <
 *    over_from (so a slot never holds two bucket numbers); the overflow list otherwise;
 *  - an id with key +inf is in none of them; an id given a NaN key is reported first;
 *  - the near heap is ordered by key, so its root is the smallest key of all (bucket()
 *    is monotonic in t). */
#ifndef GR_CALENDAR_H
#define GR_CALENDAR_H

#include <math.h>
#include <stdint.h>

/* Beyond this, bucket numbers saturate (a key that far ahead only needs to be in the
 * overflow; saturation keeps bucket() monotonic and avoids an overflowing conversion). */
#define GR_CQ_FAR 4611686018427387904.0 /* 2^62 */

/* 16 bytes, so that no item straddles two cache lines (at 24 bytes one in four did, and
 * an update then missed twice on it at large N).  Where an id is follows from prev and
 * its key: in the near heap (next is its slot there), nowhere, or in a list -- a bucket's
 * if bucket(key) < over_from, else the overflow (the invariants below). */
typedef struct {
    double t;       /* key */
    int32_t next;   /* in a list: the next id, -1 at the end; in the near heap: its slot */
    int32_t prev;   /* in a list: the previous id, -1 at its head; or GR_CQ_NEAR, GR_CQ_NONE */
} gr_cq_item;
typedef char gr_cq_item_is_16_bytes[sizeof(gr_cq_item) == 16 ? 1 : -1];

typedef struct {
    double t;
    int32_t id;
} gr_cq_near;

typedef struct {
    int32_t n;
    gr_cq_item *item;  /* n, indexed by id */
    int32_t *head;     /* nb bucket list heads, -1 if empty */
    int32_t nb;        /* a power of two, a few per id */
    double t0, inv_w;  /* bucket(t) = floor((t - t0) * inv_w) */
    int64_t cur, over_from;
    int32_t over;      /* head of the overflow list */
    int64_t n_list, n_over;
    gr_cq_near *near;  /* near heap, capacity n */
    int32_t n_near;
    int32_t nan_id;    /* an id whose key is NaN, -1 if none */
    int64_t changes, rebuild_at;
    int32_t depth;     /* the near heap is topped up below this many keys (see gr_cq_top);
                        * > 1 (a caller that prefetches): a drain asks for the next buckets */
} gr_cq;

/* Allocate a queue of n ids, all with key +inf.  Returns GR_OK or GR_ERR_NOMEM. */
int gr_cq_init(gr_cq *q, int32_t n);
void gr_cq_free(gr_cq *q);
/* Set the key of id (+inf: no event). */
void gr_cq_update(gr_cq *q, int32_t id, double t);
/* gr_cq_top when the near heap is empty, a NaN key is pending or a rebuild is due. */
int32_t gr_cq_top_slow(gr_cq *q, double *t);

/* The id with the smallest key (-1 if every key is +inf) and that key in *t; a NaN key
 * comes first.  Does not remove it, but may move the calendar forward or rebuild it.
 * Inline for the common case, the root of a near heap that holds at least `depth` keys;
 * below that it is topped up from the next buckets first (where any keys are left):
 * depth 1 refills it only when empty, the cheapest; a caller that prefetches events
 * ahead (gr_cq_ahead) sets depth to GR_CQ_AHEAD + 1, so the next ids are at hand. */
static inline int32_t gr_cq_top(gr_cq *q, double *t)
{
    if (q->n_near >= q->depth && q->nan_id < 0 && q->changes < q->rebuild_at) {
        *t = q->near[0].t;
        return q->near[0].id;
    }
    return gr_cq_top_slow(q, t);
}
/* The id most likely to be on top once the current top's key has changed (the
 * runner-up of the near heap, or the first id of the next bucket), -1 if none at hand:
 * a hint for prefetching, no promise. */
static inline int32_t gr_cq_hint(const gr_cq *q)
{
    if (q->n_near >= 3) return q->near[2].t < q->near[1].t ? q->near[2].id : q->near[1].id;
    if (q->n_near == 2) return q->near[1].id;
    return q->head[(q->cur + 1) & (q->nb - 1)];
}

/* The ids most likely to be on top after the current top, in order (next[0] the very
 * next), -1 where none is at hand: the smallest keys of the near heap below its root
 * (the k-th smallest lies within its first 2^k - 1 slots).  A hint for prefetching
 * events ahead, no promise. */
#define GR_CQ_AHEAD 3
static inline void gr_cq_ahead(const gr_cq *q, int32_t next[GR_CQ_AHEAD])
{
    double t0 = INFINITY, t1 = INFINITY, t2 = INFINITY; /* the three smallest, in order */
    int32_t i0 = -1, i1 = -1, i2 = -1;
    const int32_t m = q->n_near < 15 ? q->n_near : 15;
    for (int32_t j = 1; j < m; j++) {
        const double t = q->near[j].t;
        const int32_t id = q->near[j].id;
        if (!(t < t2)) continue;
        if (t < t1) {
            t2 = t1;
            i2 = i1;
            if (t < t0) {
                t1 = t0;
                i1 = i0;
                t0 = t;
                i0 = id;
            } else {
                t1 = t;
                i1 = id;
            }
        } else {
            t2 = t;
            i2 = id;
        }
    }
    next[0] = i0;
    next[1] = i1;
    next[2] = i2;
}

/* Ask the memory system for id's entry ahead of a gr_cq_update of it.  A macro: GCC
 * deletes calls to a function that does nothing but prefetch. */
#if defined(__GNUC__) || defined(__clang__)
#define GR_CQ_PREFETCH(q, id) __builtin_prefetch(&(q)->item[(id)])
#define GR_CQ_PREFETCH_HEAD(q, slot) __builtin_prefetch(&(q)->head[(slot)])
#else
#define GR_CQ_PREFETCH(q, id) ((void)(q), (void)(id))
#define GR_CQ_PREFETCH_HEAD(q, slot) ((void)(q), (void)(slot))
#endif

/* Ask for the bucket list head that a key t would go to (a miss at large N, whose load
 * then overlaps the caller's work before its gr_cq_update). */
static inline void gr_cq_prefetch_key(const gr_cq *q, double t)
{
    const double x = (t - q->t0) * q->inv_w;
    if (x >= 0.0 && x < GR_CQ_FAR) {
        const int64_t b = (int64_t)x;
        if (b > q->cur && b < q->over_from) GR_CQ_PREFETCH_HEAD(q, b & (q->nb - 1));
    }
}

/* After the caller renumbered its ids (id i is now newpos[i], a permutation): move
 * every key along. */
void gr_cq_renumber(gr_cq *q, const int32_t *newpos);

/* Whether q keeps the invariants above, for a queue read from outside (a checkpoint)
 * whose arrays are allocated (n ids, nb slots, near heap room for n) but whose contents
 * are not to be trusted: every id and link in range, each list free of cycles, its back
 * links right and its ids in the right buckets, the near heap ordered, every id with a
 * finite key in exactly one place.  O(n + nb).  `seen`: n bytes of zeroed scratch.
 * Returns NULL if so, else a static string naming the first fault. */
const char *gr_cq_check(const gr_cq *q, uint8_t *seen);

#endif
