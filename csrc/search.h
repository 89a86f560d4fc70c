/* search.h -- the pair searches of the event loop: who could i hit next, among the
 * adjacent cells (scan_cells), a big particle's block (scan_block) or a neighbour list
 * (scan_list); and building or mending a neighbour list (find_near, link_all, relink).
 *
 * Static functions included by edmd.c only: in the loop's translation unit the compiler
 * inlines them, or clones them for dim = 2 and dim = 3, as it does the loop's own. */
#ifndef GR_SEARCH_H
#define GR_SEARCH_H

#include <math.h>

#include "collide.h"
#include "engine.h"
#include "le_cells.h"

/* A pair that collided with each other at this very instant cannot approach again in
 * exact arithmetic (the normal relative velocity became -xi times the old one); any
 * approach left is rounding, e.g. after xi = 0. */
static inline int rebound_now(const gr_edmd *s, int32_t i, int32_t j, double t, double dt)
{
    return dt == 0.0 && s->sched[i].last == j && s->sched[j].last == i && s->sched[i].t_last == t &&
           s->sched[j].t_last == t;
}

/* the cells across a sheared face (the edge rows of a Lees-Edwards box) */
#include "lees_edwards.h"

/* One candidate j (not i) for i's next pair collision (record p): j seen through an
 * image shift (NULL: none) or, with `nearest`, through the nearest periodic image.
 * Keeps the earliest in *best / *partner; `best` is relative to i's clock and is also
 * the horizon for the early exit in gr_pair_beats.  Every scan calls this with constant
 * shift and nearest arguments, so each gets its own inlined copy. */
static GR_ALWAYS_INLINE void try_pair(const gr_edmd *s, int dyn, int dim, int32_t i, const double *p,
                                      int32_t j, const double *shift, int nearest,
                                      double *best, int32_t *partner)
{
    const double *q = rec(s, dim, j);
    double dtj = TIME(p, dim) - TIME(q, dim), dr[3], dv[3];
    for (int a = 0; a < dim; a++) {
        dr[a] = fl_sep(dyn, q[a], VEL(q, dim)[a], s->cfg.gravity[a], dtj, p[a]);
        if (shift) dr[a] += shift[a];
        if (nearest) dr[a] = bd_nearest(dr[a], s->L[a]);
        dv[a] = fl_relvel(dyn, VEL(q, dim)[a], VEL(p, dim)[a], s->cfg.gravity[a], dtj);
    }
    double dt;
    if (!fl_pair_beats(dyn, dim, dr, dv, RAD(p, dim) + RAD(q, dim), *best, &dt)) return;
    if (rebound_now(s, i, j, TIME(p, dim), dt)) return;
    *best = dt;
    *partner = j;
    GR_PREFETCH(&s->sched[j]); /* its collision count is read when the scan ends */
}

/* The earliest pair collision of i found by a scan, if it beats i's prediction. */
static inline void keep_pair(gr_edmd *s, int dim, int32_t i, double best, int32_t partner)
{
    if (partner < 0) return;
    gr_sched *e = &s->sched[i];
    e->t_coll = TIME(rec(s, dim, i), dim) + best;
    e->partner = partner;
    e->pcount = s->sched[partner].count;
}

/* Pair collisions of i with the particles of one cell, seen through an image shift. */
static inline void scan_cell(const gr_edmd *s, int dyn, int dim, int32_t i, const double *p,
                             int32_t cell, const double *shift, double *best, int32_t *partner)
{
    for (int32_t j = s->cells.head[cell]; j >= 0; j = s->cells.next[j])
        if (j != i) try_pair(s, dyn, dim, i, p, j, shift, 0, best, partner);
}

/* The pair (i, j), j seen through the nearest periodic image (the one that touches:
 * contact distances are below half the box), for scans that involve a big particle. */
static inline void scan_one(const gr_edmd *s, int dyn, int dim, int32_t i, const double *p, int32_t j,
                            double *best, int32_t *partner)
{
    if (j != i) try_pair(s, dyn, dim, i, p, j, NULL, s->cfg.periodic, best, partner);
}

static void scan_block(const gr_edmd *s, int dyn, int dim, int32_t i, int axis, int dir, double *best,
                       int32_t *partner);

/* Cell mode: pair collisions of i in all adjacent cells (axis < 0) or in the layer newly
 * adjacent after crossing along `axis` in direction `dir`, and with every big particle;
 * keep the earliest in i's prediction if it beats the one there. */
static void scan_cells(gr_edmd *s, int dyn, int dim, int32_t i, int axis, int dir)
{
    const gr_cells *g = &s->cells;
    const double *p = rec(s, dim, i);
    const int32_t *c = s->sched[i].c;
    gr_sched *e = &s->sched[i];
    double best = e->t_coll - TIME(p, dim);
    int32_t partner = -1;
    if (s->big.n && s->big.is_big[i]) {
        scan_block(s, dyn, dim, i, axis, dir, &best, &partner);
    } else if (cell_interior(g, dim, c)) {
        const int32_t base = cell_of(g, dim, c);
        /* the occupied cells, kept or not without a branch (which are occupied is as
         * good as random), read a row of three at a time where the cells form rows */
        int32_t full[27];
        int m = 0;
        if (axis == 0) {
            m = cells_occupied(g, base, g->off_layer[dir > 0], dim == 3 ? 9 : 3, full);
        } else {
            const int32_t *row = axis < 0 ? g->row_all : g->row_layer[2 * axis + (dir > 0)];
            const int rows = axis < 0 ? (dim == 3 ? 9 : 3) : (dim == 3 ? 3 : 1);
            for (int k = 0; k < rows; k++) {
                const int32_t mid = base + row[k];
                const unsigned bits = cell_row(g, mid);
                full[m] = mid - 1;
                m += bits & 1;
                full[m] = mid;
                m += (bits >> 1) & 1;
                full[m] = mid + 1;
                m += bits >> 2;
            }
        }
        /* in a grid too large for the cache, the occupied cells' heads first, all at
         * once: they are misses, and the chained loads of the scan would otherwise wait
         * for them one by one (in a small grid the loop costs more than it saves: its
         * length, the number of occupied cells, is a branch mispredicted often) */
        if (g->prefetch_heads)
            for (int k = 0; k < m; k++) GR_PREFETCH(&g->head[full[k]]);
        for (int k = 0; k < m; k++) scan_cell(s, dyn, dim, i, p, full[k], NULL, &best, &partner);
    } else if (s->le && le_edge_row(g, c[1])) {
        le_scan_edge(s, dyn, dim, i, &best, &partner);
    } else {
        gr_nbr nb[27];
        int count = cell_neighbours(g, dim, c, axis, dir, nb);
        for (int k = 0; k < count; k++)
            scan_cell(s, dyn, dim, i, p, nb[k].cell, nb[k].shift, &best, &partner);
    }
    for (int32_t b = 0; b < s->big.n; b++) scan_one(s, dyn, dim, i, p, s->big.idx[b], &best, &partner);
    keep_pair(s, dim, i, best, partner);
}

/* Cell mode, at large N, prefetching events ahead: the cells the next event of i will
 * scan (i's scheduling state must be at hand) -- the layer newly adjacent to the cell a
 * crossing enters, or every adjacent cell before a collision -- as a base cell and
 * offsets (away from the box edge only, the common case: returns 0 elsewhere). */
static inline int next_scan(const gr_edmd *s, int dim, int32_t i, int32_t *base,
                            const int32_t **off)
{
    const gr_cells *g = &s->cells;
    const gr_sched *e = &s->sched[i];
    int32_t c[3] = {e->c[0], e->c[1], e->c[2]};
    int count = dim == 3 ? 27 : 9;
    *base = 0; /* defined even where no cells are returned */
    *off = g->off_all;
    if (e->cross < 0) return 0;
    if (e->t_cross < e->t_coll) {
        const int a = e->cross >> 1, up = e->cross & 1;
        c[a] += up ? 1 : -1;
        *off = g->off_layer[2 * a + up];
        count = dim == 3 ? 9 : 3;
    }
    if (!cell_interior(g, dim, c)) return 0;
    *base = cell_of(g, dim, c);
    return count;
}

/* Two events ahead: ask for the heads of the occupied cells i's next event will scan
 * (and of the cell a crossing enters), and note those cells for prefetch_firsts. */
static inline void prefetch_heads(gr_edmd *s, int dim, int32_t i)
{
    int32_t base;
    const int32_t *off;
    const int count = next_scan(s, dim, i, &base, &off);
    if (count) GR_PREFETCH(&s->cells.head[base]);
    const int m = cells_occupied(&s->cells, base, off, count, s->ahead_cells);
    for (int k = 0; k < m; k++) GR_PREFETCH(&s->cells.head[s->ahead_cells[k]]);
    s->ahead_m = m;
}

/* One event ahead, the heads asked for by prefetch_heads being at hand: ask for the
 * first particle of each of those cells (most hold one at most; a cell emptied since
 * has head -1). */
static inline void prefetch_firsts(const gr_edmd *s, int dim)
{
    for (int k = 0; k < s->ahead_m; k++) {
        const int32_t j = s->cells.head[s->ahead_cells[k]];
        if (j < 0) continue;
        GR_PREFETCH(rec(s, dim, j));
        GR_PREFETCH(&s->cells.next[j]);
    }
}

/* Cell mode, big particle i: the cells within its reach, the block of R cells each way
 * (axis < 0), or the layer of it newly reached after crossing along `axis` in direction
 * `dir`.  gr_big_choose keeps the block narrower than the box, so a periodic block never
 * meets itself. */
static void scan_block(const gr_edmd *s, int dyn, int dim, int32_t i, int axis, int dir, double *best,
                       int32_t *partner)
{
    const gr_cells *g = &s->cells;
    const double *p = rec(s, dim, i);
    const int32_t *c = s->sched[i].c;
    int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < dim; a++) {
        int32_t reach = (int32_t)ceil((RAD(p, dim) + s->big.r_small) / g->w[a]);
        lo[a] = a == axis ? c[a] + dir * reach : c[a] - reach;
        hi[a] = a == axis ? lo[a] : c[a] + reach;
        if (!s->cfg.periodic) { /* walls: the block ends at them */
            if (lo[a] < 0) lo[a] = 0;
            if (hi[a] > g->nc[a] - 1) hi[a] = g->nc[a] - 1;
            if (lo[a] > hi[a]) return; /* the layer lies beyond a wall */
        }
    }
    /* beyond dim, lo = hi = 0 and nc = 1: one pass */
    int32_t q[3] = {0, 0, 0};
    for (int32_t k2 = lo[2]; k2 <= hi[2]; k2++) {
        q[2] = bd_cell_wrap(k2, g->nc[2]);
        for (int32_t k1 = lo[1]; k1 <= hi[1]; k1++) {
            q[1] = bd_cell_wrap(k1, g->nc[1]);
            for (int32_t k0 = lo[0]; k0 <= hi[0]; k0++) {
                q[0] = bd_cell_wrap(k0, g->nc[0]);
                int32_t cell = cell_of(g, dim, q);
                if (!cell_occupied(g, cell)) continue;
                for (int32_t j = g->head[cell]; j >= 0; j = g->next[j])
                    scan_one(s, dyn, dim, i, p, j, best, partner);
            }
        }
    }
}

/* List mode: pair collisions of i with its listed neighbours, before its predicted wall
 * collision and its shell exit (which rebuilds and predicts afresh, so later collisions
 * need not be found now: most candidates then fail the cheap test). */
static void scan_list(gr_edmd *s, int dyn, int dim, int32_t i)
{
    const double *p = rec(s, dim, i);
    gr_sched *e = &s->sched[i];
    const int32_t *row = nl_row(&s->nl, i);
    double best = (e->t_coll < e->t_cross ? e->t_coll : e->t_cross) - TIME(p, dim);
    int32_t partner = -1;
    for (int k = 0; k < e->nn; k++)
        try_pair(s, dyn, dim, i, p, row[k] >> GR_NL_BITS, s->nl.img[row[k] & GR_NL_CODE_MASK], 0,
                 &best, &partner);
    keep_pair(s, dim, i, best, partner);
}

/* scan_list four candidates at a time, for x86-64 CPUs with AVX2 (chosen in edmd.c) */
#include "scan_avx2.h"

/* List mode: make i's position (in the box) its list centre and file it in that cell. */
static inline void set_centre(gr_edmd *s, int dim, int32_t i)
{
    const double *p = rec(s, dim, i);
    double *centre = s->nl.centre + (size_t)i * (dim + 1);
    centre[dim] = RAD(p, dim);
    for (int a = 0; a < dim; a++) centre[a] = p[a];
    cell_coords(&s->cells, dim, p, s->sched[i].c);
    if (s->nl.built) { /* sheared: filed where the flow carries it (le_cells.h) */
        s->nl.built[i] = TIME(p, dim);
        le_expiry(s, centre, TIME(p, dim), s->nl.expiry + 2 * (size_t)i);
        s->sched[i].c[0] = le_file(&s->cells, &s->nl, centre, &s->nl.lap[i], p[0], TIME(p, dim));
    }
}

/* List mode, for find_near: append to s->nl.near (m entries so far) every particle j of
 * one cell, seen through an image shift (NULL: none) with image code `code`, whose centre
 * is within cj[dim] + reach of ci; kept or not without a branch (about one candidate in
 * six is kept: as good as random).  Returns the new count. */
static GR_ALWAYS_INLINE int32_t near_in_cell(const gr_edmd *s, int dim, int32_t i,
                                             const double *ci, double reach, int32_t cell,
                                             const double *shift, int32_t code, int above,
                                             int32_t m)
{
    const gr_cells *g = &s->cells;
    int32_t *near = s->nl.near;
    for (int32_t j = g->head[cell]; j >= 0; j = g->next[j]) {
        const double *cj = s->nl.centre + (size_t)j * (dim + 1);
        double d2 = 0.0;
        for (int a = 0; a < dim; a++) {
            const double d = (shift ? cj[a] + shift[a] : cj[a]) - ci[a];
            d2 = a ? d2 + d * d : d * d; /* from the first term (collide.h) */
        }
        const double cut = cj[dim] + reach;
        near[m] = (j << GR_NL_BITS) | code;
        m += (d2 < cut * cut) & (j != i) & (!above | (j > i));
    }
    return m;
}

static int32_t le_find_near(gr_edmd *s, int dim, int32_t i, int above);

/* List mode: every particle whose centre is within r_i + r_j + 2 delta of i's (only those
 * numbered above i if `above`: building all lists at once), as list entries in s->nl.near;
 * returns how many. */
static int32_t find_near(gr_edmd *s, int dim, int32_t i, int above)
{
    const gr_cells *g = &s->cells;
    const double *ci = s->nl.centre + (size_t)i * (dim + 1);
    const double reach = ci[dim] + 2.0 * s->nl.shell;
    /* first the new neighbours (near_in_cell), then the links */
    int32_t m = 0;
    if (s->le) return le_find_near(s, dim, i, above);
    if (cell_interior(g, dim, s->sched[i].c)) {
        /* away from the box edge (the common case): no image shifts, no wrapping */
        const int32_t base = cell_of(g, dim, s->sched[i].c);
        for (int k = 0; k < (dim == 3 ? 27 : 9); k++) {
            const int32_t cell = base + g->off_all[k];
            if (cell_occupied(g, cell))
                m = near_in_cell(s, dim, i, ci, reach, cell, NULL, GR_NL_CODE_NONE(dim), above, m);
        }
        return m;
    }
    gr_nbr nb[27];
    const int count = cell_neighbours(g, dim, s->sched[i].c, -1, 0, nb);
    for (int k = 0; k < count; k++) {
        const int32_t code = nl_code(dim, nb[k].shift);
        m = near_in_cell(s, dim, i, ci, reach, nb[k].cell, nb[k].shift, code, above, m);
    }
    return m;
}

/* The error of a list that could not grow. */
static int link_failed(const gr_edmd *s, int32_t i, int status, gr_error *err)
{
    gr_error_set(err, status, uid(s, i), -1, s->t, (double)s->nl.cap,
                 "a neighbour list could not grow (out of memory, or past "
                 GR_XSTR(GR_NL_CAP_MAX) " entries); the system cannot go on");
    return status;
}

/* List mode: link i with the m neighbours find_near found (in s->nl.near), both ways. */
static int link_all(gr_edmd *s, int dim, int32_t i, int32_t m, gr_error *err)
{
    const int32_t *near = s->nl.near;
    for (int32_t k = 0; k < m; k++) {
        int status = nl_link(&s->nl, dim, s->n, s->sched, i, near[k] >> GR_NL_BITS,
                             near[k] & GR_NL_CODE_MASK);
        if (status != GR_OK) return link_failed(s, i, status, err);
    }
    return GR_OK;
}

/* List mode, a shell exit that did not bring i back into the box: i's list becomes the m
 * neighbours find_near found, and only the neighbours that leave or join it have their
 * rows changed.  Most of i's neighbours stay (its centre moved by delta, its reach is
 * sigma + 2 delta), and each keeps its entry of i as it is: with neither centre moved
 * into the box since that entry was made, the image that brings i next to it is the same
 * (two images cannot both be within reach: the box is wider than twice the reach,
 * build.c).  So a shell exit reads and writes i's row and the rows of those few, where
 * taking i off every neighbour's row and appending it again searched each of them. */
static int relink(gr_edmd *s, int dim, int32_t i, int32_t m, gr_error *err)
{
    gr_nlist *nl = &s->nl;
    gr_sched *e = &s->sched[i];
    const int32_t *near = nl->near, *row = nl_row(nl, i);
    const int listed = e->nn; /* a local: the marks' byte stores may alias anything */
    uint8_t *mark = nl->mark; /* all 0 between shell exits */
    for (int k = 0; k < listed; k++) mark[row[k] >> GR_NL_BITS] = 1;
    for (int32_t k = 0; k < m; k++) {
        uint8_t *mk = &mark[near[k] >> GR_NL_BITS];
        *mk = *mk ? 2 : 0; /* listed and staying: 2; joining: 0 */
    }
    for (int k = 0; k < listed; k++) { /* leaving (still 1): off their rows */
        const int32_t j = row[k] >> GR_NL_BITS;
        if (mark[j] == 1) {
            nl_unlink(nl, s->sched, j, i);
            mark[j] = 0;
        }
    }
    e->nn = 0;
    for (int32_t k = 0; k < m; k++) {
        const int32_t j = near[k] >> GR_NL_BITS, code = near[k] & GR_NL_CODE_MASK;
        int status = GR_OK;
        if (mark[j]) { /* staying: its row keeps i's entry */
            mark[j] = 0;
            if (e->nn == nl->cap) status = gr_nlist_grow(nl, s->n, s->sched);
            if (status == GR_OK) nl_row(nl, i)[e->nn++] = near[k];
        } else {
            status = nl_link(nl, dim, s->n, s->sched, i, j, code);
        }
        if (status != GR_OK) return link_failed(s, i, status, err);
    }
    return GR_OK;
}

/* the neighbour lists of a sheared box */
#include "le_nlist.h"

#endif
