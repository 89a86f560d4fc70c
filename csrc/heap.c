/* heap.c -- indexed binary min-heap; see heap.h for the invariants. */
#include <math.h>
#include <stdlib.h>

#include "common.h"
#include "heap.h"

int gr_heap_init(gr_heap *h, int32_t n)
{
    h->n = n;
    h->node = malloc((size_t)(n > 0 ? n : 1) * sizeof *h->node);
    h->where = malloc((size_t)(n > 0 ? n : 1) * sizeof *h->where);
    if (!h->node || !h->where) {
        gr_heap_free(h);
        return GR_ERR_NOMEM;
    }
    for (int32_t k = 0; k < n; k++) {
        h->node[k].t = INFINITY;
        h->node[k].id = k;
        h->where[k] = k;
    }
    if (n == 0) { h->node[0].t = INFINITY; h->node[0].id = -1; }
    return GR_OK;
}

void gr_heap_free(gr_heap *h)
{
    free(h->node);
    free(h->where);
    h->node = NULL;
    h->where = NULL;
}

/* The moving node is held in a register and written once at its final slot; the nodes
 * it passes are shifted by one level. */
void gr_heap_update(gr_heap *h, int32_t id, double t)
{
    gr_heap_node *node = h->node;
    int32_t *where = h->where;
    int32_t k = where[id];
    const int32_t n = h->n;

    if (k > 0 && t < node[(k - 1) >> 1].t) {
        do {
            int32_t parent = (k - 1) >> 1;
            if (!(t < node[parent].t)) break;
            node[k] = node[parent];
            where[node[k].id] = k;
            k = parent;
        } while (k > 0);
    } else {
        for (;;) {
            int32_t c = 2 * k + 1;
            if (c >= n) break;
            if (c + 1 < n && node[c + 1].t < node[c].t) c++;
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
