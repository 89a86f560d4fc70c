/* big.c -- which particles are big (big.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "big.h"
#include "cells.h"
#include "common.h"

static int cmp_radius(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int gr_big_cut(const double *radius, int32_t n, double ratio, double *cut)
{
    double *sorted = malloc((size_t)n * sizeof *sorted);
    if (!sorted) return GR_ERR_NOMEM;
    memcpy(sorted, radius, (size_t)n * sizeof *sorted);
    qsort(sorted, (size_t)n, sizeof *sorted, cmp_radius);
    *cut = ratio * sorted[n / 2];
    free(sorted);
    return GR_OK;
}

int gr_big_choose(gr_big *b, int dim, int32_t n, const double *radius, const double *L,
                  double ratio, double cell_factor)
{
    double rmax = 0.0;
    for (int32_t i = 0; i < n; i++) rmax = radius[i] > rmax ? radius[i] : rmax;
    b->r_small = rmax;
    b->n = 0;
    if (!(ratio < INFINITY) || n < 2) return GR_OK;
    double cut;
    if (gr_big_cut(radius, n, ratio, &cut) != GR_OK) return GR_ERR_NOMEM;
    int32_t count = 0;
    double r_small = 0.0;
    for (int32_t i = 0; i < n; i++) {
        if (radius[i] > cut) count++;
        else if (radius[i] > r_small) r_small = radius[i];
    }
    if (count == 0 || count > GR_BIG_MAX) return GR_OK;
    double k[3];
    gr_cells_dims(dim, n, L, 2.0 * r_small * cell_factor, k);
    for (int a = 0; a < dim; a++) {
        double reach = ceil((rmax + r_small) / (L[a] / k[a]));
        if (!(2.0 * reach + 3.0 <= k[a])) return GR_OK;
    }
    for (int32_t i = 0; i < n; i++)
        if (radius[i] > cut) {
            b->is_big[i] = 1;
            b->idx[b->n++] = i;
        }
    b->r_small = r_small;
    return GR_OK;
}
