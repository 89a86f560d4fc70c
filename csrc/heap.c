/* heap.c -- indexed 4-ary min-heap; see heap.h for the invariants.
 *
 * Four children per node halve the depth of a binary heap, and the four children of a
 * node share one cache line (4 x 16 bytes): a sift-down touches half as many lines.
 * The node array is padded with +inf keys so that picking the smallest child needs no
 * bounds test. */
#define _POSIX_C_SOURCE 200112L /* posix_memalign */
#include <math.h>
#include <stdlib.h>

#include "common.h"
#include "heap.h"

#define GR_HEAP_PAD 4

int gr_heap_init(gr_heap *h, int32_t n)
{
    h->n = n;
    void *mem = NULL;
    h->raw = posix_memalign(&mem, 64, ((size_t)n + GR_HEAP_PAD + 3) * sizeof *h->node) == 0 ? mem : NULL;
    h->where = malloc((size_t)(n > 0 ? n : 1) * sizeof *h->where);
    if (!h->raw || !h->where) {
        gr_heap_free(h);
        return GR_ERR_NOMEM;
    }
    /* children 4k+1..4k+4 of node k share a 64-byte line when node[1] starts one */
    h->node = h->raw + 3;
    for (int32_t k = 0; k < n + GR_HEAP_PAD; k++) {
        h->node[k].t = INFINITY;
        h->node[k].id = k < n ? k : -1;
        if (k < n) h->where[k] = k;
    }
    return GR_OK;
}

void gr_heap_free(gr_heap *h)
{
    free(h->raw);
    free(h->where);
    h->raw = NULL;
    h->node = NULL;
    h->where = NULL;
}

/* The moving node is held in registers and written once at its final slot; the nodes
 * it passes are shifted by one level. */
void gr_heap_update(gr_heap *h, int32_t id, double t)
{
    gr_heap_node *node = h->node;
    int32_t *where = h->where;
    int32_t k = where[id];
    const int32_t n = h->n;

    if (k > 0 && t < node[(k - 1) >> 2].t) {
        do {
            int32_t parent = (k - 1) >> 2;
            if (!(t < node[parent].t)) break;
            node[k] = node[parent];
            where[node[k].id] = k;
            k = parent;
        } while (k > 0);
    } else {
        for (;;) {
            int32_t c = 4 * k + 1;
            if (c >= n) break;
            /* smallest of the four children; padding keys are +inf */
            int32_t a = c + (node[c + 1].t < node[c].t);
            int32_t b = c + 2 + (node[c + 3].t < node[c + 2].t);
            c = node[b].t < node[a].t ? b : a;
            if (!(node[c].t < t)) break;
            node[k] = node[c];
            where[node[k].id] = k;
            k = c;
        }
    }
    node[k].t = t;
    node[k].id = id;
    where[id] = k;
}
