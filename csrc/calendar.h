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
 * rebuilds itself every few N key changes, so it follows a system that cools or heats.
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

#include <stdint.h>

typedef struct {
    double t;       /* key */
    int32_t next;   /* links in a bucket or overflow list, -1 at the ends */
    int32_t prev;
    int32_t where;  /* >= 0: slot in the near heap; or GR_CQ_LIST / GR_CQ_OVER / GR_CQ_NONE */
    int32_t pad;
} gr_cq_item;

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
 * Inline for the common case, the root of a non-empty near heap. */
static inline int32_t gr_cq_top(gr_cq *q, double *t)
{
    if (q->n_near > 0 && q->nan_id < 0 && q->changes < q->rebuild_at) {
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

/* Ask the memory system for id's entry ahead of a gr_cq_update of it.  A macro: GCC
 * deletes calls to a function that does nothing but prefetch. */
#if defined(__GNUC__) || defined(__clang__)
#define GR_CQ_PREFETCH(q, id) __builtin_prefetch(&(q)->item[(id)])
#else
#define GR_CQ_PREFETCH(q, id) ((void)(q), (void)(id))
#endif

/* After the caller renumbered its ids (id i is now newpos[i], a permutation): move
 * every key along. */
void gr_cq_renumber(gr_cq *q, const int32_t *newpos);

#endif
