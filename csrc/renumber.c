/* renumber.c -- renumbering the particles in cell order.
 *
 * At large N the per-particle arrays are far out of cache and each event touches a
 * particle and its neighbours; numbered in cell order now and then, particles in
 * adjacent cells are close in memory.  Only the numbering changes -- positions,
 * velocities, predictions and the order of events stay exactly as they were -- and
 * id_of maps back to the caller's numbering. */
#define _DEFAULT_SOURCE         /* madvise (hugemem.h) */
#define _POSIX_C_SOURCE 200112L /* posix_memalign */
#include <stdlib.h>
#include <string.h>

#include "engine.h"
#include "hugemem.h"
#include "le_cells.h"

/* A counting sort by cell, O(N + cells), permuting every per-particle array and
 * remapping every stored particle index: partners, the queue, the cell lists, the
 * neighbour lists, the big particles. */
int gr_renumber(gr_edmd *s)
{
    const int32_t n = s->n;
    const int d = s->dim;
    gr_cells *g = &s->cells;
    const int lists = s->nl.shell > 0.0;
    if (!s->order.scratch) return GR_OK;
    int32_t *start = calloc((size_t)g->ncells + 1, sizeof *start);
    int32_t *newpos = malloc((size_t)n * sizeof *newpos);
    int32_t *rows = lists ? gr_big_alloc((size_t)n * s->nl.cap * sizeof *rows) : NULL;
    if (!start || !newpos || (lists && !rows)) {
        free(start);
        free(newpos);
        free(rows);
        return GR_ERR_NOMEM;
    }
    for (int32_t i = 0; i < n; i++) {
        const int32_t c = cell_of(g, d, s->sched[i].c);
        newpos[i] = c; /* the cell, for now */
        start[c + 1]++;
    }
    for (int32_t c = 0; c < g->ncells; c++) start[c + 1] += start[c];
    for (int32_t i = 0; i < n; i++) newpos[i] = start[newpos[i]]++;
    free(start);

#define PERMUTE(arr, type, width)                                                       \
    do {                                                                                \
        type *tmp = (type *)s->order.scratch;                                           \
        for (int32_t i = 0; i < n; i++)                                                 \
            memcpy(tmp + (size_t)newpos[i] * (width), (arr) + (size_t)i * (width),      \
                   (width) * sizeof(type));                                             \
        memcpy((arr), tmp, (size_t)n * (width) * sizeof(type));                          \
    } while (0)
    PERMUTE(s->P, double, (size_t)GR_STRIDE(s->dim));
    PERMUTE(s->mass, double, 1);
    if (s->spin) PERMUTE(s->spin, double, (size_t)GR_SPIN_DIM(d));
    PERMUTE(s->image, int64_t, (size_t)d);
    PERMUTE(s->order.id_of, int32_t, 1);
    PERMUTE(s->big.is_big, uint8_t, 1);
    if (lists) PERMUTE(s->nl.centre, double, (size_t)d + 1);
    if (s->nl.built) {
        PERMUTE(s->nl.built, double, 1);
        PERMUTE(s->nl.lap, int8_t, 1);
        PERMUTE(s->nl.expiry, double, 2);
    }
#undef PERMUTE
    if (lists) {
        for (int32_t i = 0; i < n; i++) {
            const int32_t *from = nl_row(&s->nl, i);
            int32_t *to = rows + (size_t)newpos[i] * s->nl.cap;
            for (int k = 0; k < s->sched[i].nn; k++) {
                const int32_t code = from[k] & GR_NL_CODE_MASK;
                to[k] = (newpos[from[k] >> GR_NL_BITS] << GR_NL_BITS) | code;
            }
        }
        free(s->nl.rows);
        s->nl.rows = rows;
    }
    for (int32_t b = 0; b < s->big.n; b++) s->big.idx[b] = newpos[s->big.idx[b]];
    {
        gr_sched *tmp = s->order.scratch;
        for (int32_t i = 0; i < n; i++) {
            gr_sched e = s->sched[i];
            if (e.partner >= 0) e.partner = newpos[e.partner];
            if (e.last >= 0) e.last = newpos[e.last];
            tmp[newpos[i]] = e;
        }
        memcpy(s->sched, tmp, (size_t)n * sizeof *tmp);
    }
    gr_cq_renumber(&s->queue, newpos);
    free(newpos);
    gr_cells_clear(g);
    for (int32_t i = n - 1; i >= 0; i--) { /* lists in increasing index order */
        if (s->big.is_big[i]) continue;
        cell_insert(g, i, cell_of(g, d, s->sched[i].c));
    }
    if (s->nl.blocks) le_sync_all(g, s->nl.blocks);
    s->order.next = s->events + (int64_t)GR_RENUMBER_EVENTS_PER_N * n;
    return GR_OK;
}
