/* cells.c -- building and freeing the cell grid (cells.h). */
#define _DEFAULT_SOURCE         /* madvise (hugemem.h) */
#define _POSIX_C_SOURCE 200112L /* posix_memalign */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "boundary.h"
#include "cells.h"
#include "hugemem.h"


/* Cells per axis: at least `width` wide, and not more cells than a few per particle (a
 * dilute gas in a big box must not allocate a huge empty grid; wider cells are always
 * correct, only slower to scan). */
double gr_cells_dims(int dim, int64_t n, const double *L, double width, double k[3])
{
    const double cap = 8.0 * (double)n + 64.0;
    double total = 1.0;
    k[0] = k[1] = k[2] = 1.0;
    for (int a = 0; a < dim; a++) {
        k[a] = floor(L[a] / width);
        if (!(k[a] >= 1.0)) k[a] = 1.0;
        if (k[a] > 1e9) k[a] = 1e9;
        total *= k[a];
    }
    /* Fewer, wider cells until the grid fits the cap: each pass shrinks the total by
     * about total / cap, and k = 1 on every axis always fits. */
    while (total > cap) {
        double f = pow(total / cap, 1.0 / dim);
        total = 1.0;
        for (int a = 0; a < dim; a++) {
            k[a] = floor(k[a] / f);
            if (k[a] < 1.0) k[a] = 1.0;
            total *= k[a];
        }
    }
    return total;
}

int gr_cells_build(gr_cells *g, int dim, int32_t n, const double *lo, const double *L,
                   int periodic, double width, gr_error *err)
{
    double k[3];
    double total = gr_cells_dims(dim, n, L, width, k);
    if (total > (double)(INT32_MAX / 2)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, total, "too many cells for the particle count");
        return GR_ERR_VALUE;
    }
    g->periodic = periodic;
    g->ncells = 1;
    for (int a = 0; a < 3; a++) {
        g->lo[a] = a < dim ? lo[a] : 0.0;
        if (a >= dim) { g->nc[a] = 1; g->w[a] = 1.0; continue; }
        g->nc[a] = (int)k[a];
        g->w[a] = L[a] / g->nc[a];
        g->ncells *= g->nc[a];
    }
    g->head = gr_big_alloc((size_t)g->ncells * sizeof *g->head);
    g->prefetch_heads = (size_t)g->ncells * sizeof *g->head > GR_HEADS_CACHED;
    g->occ = calloc(cell_occ_words(g->ncells), sizeof *g->occ);
    g->next = gr_big_alloc((size_t)n * sizeof *g->next);
    if (!g->head || !g->occ || !g->next) return GR_ERR_NOMEM;
    for (int32_t c = 0; c < g->ncells; c++) g->head[c] = -1;
    int k_all = 0, k_layer[6] = {0, 0, 0, 0, 0, 0};
    int r_all = 0, r_layer[6] = {0, 0, 0, 0, 0, 0};
    for (int d2 = (dim == 3 ? -1 : 0); d2 <= (dim == 3 ? 1 : 0); d2++)
        for (int d1 = -1; d1 <= 1; d1++)
            for (int d0 = -1; d0 <= 1; d0++) {
                int32_t off = d0 + g->nc[0] * (d1 + g->nc[1] * d2);
                int dd[3] = {d0, d1, d2};
                g->off_all[k_all++] = off;
                if (d0 == 0) g->row_all[r_all++] = off;
                for (int a = 0; a < dim; a++)
                    if (dd[a] != 0) {
                        int layer = 2 * a + (dd[a] > 0);
                        g->off_layer[layer][k_layer[layer]++] = off;
                        if (a > 0 && d0 == 0) g->row_layer[layer][r_layer[layer]++] = off;
                    }
            }
    for (int a = 0; a < dim; a++) {
        int m = g->nc[a];
        g->nb_cell[a] = malloc((size_t)3 * m * sizeof(int32_t));
        g->nb_shift[a] = malloc((size_t)3 * m * sizeof(double));
        if (!g->nb_cell[a] || !g->nb_shift[a]) return GR_ERR_NOMEM;
        for (int c = 0; c < m; c++) {
            for (int dd = -1; dd <= 1; dd++) {
                double shift;
                const int q = bd_cell_step(c + dd, m, periodic, L[a], &shift);
                g->nb_cell[a][3 * c + dd + 1] = q;
                g->nb_shift[a][3 * c + dd + 1] = shift;
            }
        }
    }
    return GR_OK;
}

void gr_cells_clear(gr_cells *g)
{
    for (int32_t c = 0; c < g->ncells; c++) g->head[c] = -1;
    memset(g->occ, 0, cell_occ_words(g->ncells) * sizeof *g->occ);
}

void gr_cells_free(gr_cells *g)
{
    free(g->head);
    free(g->occ);
    free(g->next);
    for (int a = 0; a < 3; a++) {
        free(g->nb_cell[a]);
        free(g->nb_shift[a]);
    }
}
