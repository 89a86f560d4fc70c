/* calendar.h -- an indexed calendar queue of event times, one key per id.
 *
 * The queue knows no physics: it maps an id to one key (the time of that id's next
 * event, +inf for none) and answers "which id has the smallest key".  An indexed binary
 * or 4-ary heap does this in O(log N) per change, and at large N every level of a sift
 * is a cache miss.  Here time is cut into buckets of width w: keys in the current bucket
 * sit in a small binary heap (the "near" heap, a handful of entries), keys in the next
 * nb - 1 buckets or so in one slot per bucket, and keys further ahead in one overflow
 * list.  A slot is an array of up to GR_CQ_WAYS ids, with a doubly linked list for the
 * rare ids beyond that.  A change of key is a removal and an insertion, O(1), touching
 * the id's entry and two slots -- not, as linked bucket lists did, the ids that happen
 * to share the buckets (each one more cache miss at large N).  The near heap is refilled
 * from the next slot when it runs empty.  w is chosen from the spread of the keys whenever the queue is rebuilt
 * (so that a bucket holds a few keys), and the queue rebuilds itself every few N key
 * changes, so it follows a system that cools or heats.
 *
 * Invariants (cur = the current bucket number, over_from = the first bucket number of
 * the overflow, cur < over_from <= cur + nb, bucket(t) = floor((t - t0) / w)):
 *  - every id with a finite key is in exactly one place: the near heap iff
 *    bucket(key) <= cur; slot bucket(key) mod nb iff cur < bucket(key) < over_from (so
 *    a slot never holds two bucket numbers); the overflow list otherwise.  Where an id
 *    is thus follows from its key, and entries store no place; the near heap keeps its
 *    ids' places in `pos` only while it is large (`track`), and is searched otherwise;
 *  - an id goes to its slot's extra list when the ways are full or the extra list is
 *    not empty, so the extra list holds ids placed after all of the ways' ids: newest
 *    first, a slot's ids are its extra list, then its ways from the last -- the order
 *    one linked list per bucket had, so the near heap, and with it the order in which
 *    equal keys come out, is what it always was;
 *  - an id with key +inf is in none of them; an id given a NaN key is reported first;
 *  - the near heap is ordered by key, so its root is the smallest key of all (bucket()
 *    is monotonic in t). */
#ifndef GR_CALENDAR_H
#define GR_CALENDAR_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    double t;       /* key */
    int32_t next;   /* links in a slot's extra list or the overflow list, -1 at the ends */
    int32_t prev;
} gr_cq_item;

/* ids one slot holds: 16 bytes, so the slots of the buckets just ahead, where most
 * keys go, stay few cache lines (keys in the slot too, 64 bytes, missed more often) */
#define GR_CQ_WAYS 3
typedef struct {
    int32_t id[GR_CQ_WAYS]; /* in the order they were placed */
    int32_t n;              /* ways in use */
} gr_cq_slot;
typedef char gr_cq_slot_size[sizeof(gr_cq_slot) == 16 ? 1 : -1];

typedef struct {
    double t;
    int32_t id;
} gr_cq_near;

typedef struct {
    int32_t n;
    gr_cq_item *item;  /* n, indexed by id */
    gr_cq_slot *slot;  /* nb, one per bucket number mod nb */
    int32_t *head;     /* nb heads of the slots' extra lists, -1 if empty */
    int32_t nb;        /* a power of two, about one per id */
    double t0, inv_w;  /* bucket(t) = floor((t - t0) * inv_w) */
    int64_t cur, over_from;
    int32_t over;      /* head of the overflow list */
    int64_t n_list, n_over; /* keys in the slots, in the overflow */
    gr_cq_near *near;  /* near heap, capacity n */
    int32_t n_near;
    int32_t track;     /* pos is kept: the heap outgrew GR_CQ_NEAR_SEARCH since it last
                        * ran empty */
    int32_t *pos;      /* n: an id's place in the near heap, while `track` */
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
 * runner-up of the near heap, or an id of the next bucket), -1 if none at hand: a hint
 * for prefetching, no promise. */
static inline int32_t gr_cq_hint(const gr_cq *q)
{
    if (q->n_near >= 3) return q->near[2].t < q->near[1].t ? q->near[2].id : q->near[1].id;
    if (q->n_near == 2) return q->near[1].id;
    const gr_cq_slot *next = &q->slot[(q->cur + 1) & (q->nb - 1)];
    return next->n > 0 ? next->id[0] : -1;
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

/* Bytes the queue takes per id (for the engine's memory estimate). */
size_t gr_cq_bytes_per_id(void);

#endif
