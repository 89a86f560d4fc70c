/* heap.h -- an indexed 4-ary min-heap of event times, one slot per particle.
 *
 * The queue knows no physics: it maps a particle id to one key (the time of that
 * particle's next event) and answers "which id has the smallest key".  Keys live in the
 * heap array beside their ids so that sifting touches one contiguous array; `where[id]`
 * gives each id's slot so a key can be changed in O(log N) without searching.
 * Invariant: every id 0..n-1 is in the heap exactly once (an id with no event has key
 * +inf), and node[k].t <= node[child].t for every slot k (children 4k+1 .. 4k+4). */
#ifndef GR_HEAP_H
#define GR_HEAP_H

#include <stdint.h>

typedef struct {
    double t;
    int32_t id;
} gr_heap_node;

typedef struct {
    int32_t n;
    gr_heap_node *node; /* n slots (+ padding), node[0] is the minimum */
    gr_heap_node *raw;  /* the allocation node points into */
    int32_t *where;     /* where[id] = slot of id */
} gr_heap;

/* Allocate a heap of n ids, all with key +inf.  Returns GR_OK or GR_ERR_NOMEM. */
int gr_heap_init(gr_heap *h, int32_t n);
void gr_heap_free(gr_heap *h);
/* Set the key of id and restore the heap order. */
void gr_heap_update(gr_heap *h, int32_t id, double t);

static inline int32_t gr_heap_top(const gr_heap *h) { return h->node[0].id; }
static inline double gr_heap_top_time(const gr_heap *h) { return h->node[0].t; }

#endif
