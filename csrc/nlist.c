/* nlist.c -- allocation and growth of the neighbour lists (nlist.h). */
#define _DEFAULT_SOURCE         /* madvise (hugemem.h) */
#define _POSIX_C_SOURCE 200112L /* posix_memalign */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "boundary.h"
#include "hugemem.h"
#include "nlist.h"

int gr_nlist_init(gr_nlist *nl, int dim, int32_t n, double shell, const double *L)
{
    nl->shell = shell;
    /* leave a hair early: two particles each within delta (1 - 1e-9) of centres more
     * than sigma + 2 delta apart stay apart by more than rounding */
    nl->exit2 = shell * (1.0 - 1e-9) * shell * (1.0 - 1e-9);
    nl->cap = GR_NL_CAP_START(dim);
    nl->centre = gr_big_alloc((size_t)n * (dim + 1) * sizeof *nl->centre);
    nl->rows = gr_big_alloc((size_t)n * nl->cap * sizeof *nl->rows);
    nl->near = malloc(((size_t)n + 4) * sizeof *nl->near); /* 4 past: le_test_avx2 */
    nl->mark = calloc((size_t)n, 1);
    for (int code = 0; code < 32; code++)
        for (int a = 0, k = code; a < 4; a++, k /= 3)
            nl->img[code][a] = a < dim ? bd_shift(k % 3 - 1, L[a]) : 0.0;
    return nl->centre && nl->rows && nl->near && nl->mark ? GR_OK : GR_ERR_NOMEM;
}

double gr_nlist_shear_strain(int dim, const double *L, double sigma_max, double shell)
{
    double lmin = L[0];
    for (int a = 1; a < dim; a++) lmin = fmin(lmin, L[a]);
    /* e^(strain / 2) (sigma + 2 delta) + 2 delta within 0.49 L (nlist.h), at most 1 */
    const double room = (0.49 * lmin - 2.0 * shell) / (sigma_max + 2.0 * shell);
    return room > 1.0 ? fmin(1.0, 2.0 * log(room)) : 0.0;
}

int gr_nlist_shear(gr_nlist *nl, int dim, int32_t n, double rate, const double *lo,
                   const double *L, double sigma_max)
{
    nl->rate = rate;
    nl->yc = lo[1] + 0.5 * L[1];
    nl->r_max = 0.5 * sigma_max;
    nl->life = 0.999 * fmin(GR_NL_STRAIN, gr_nlist_shear_strain(dim, L, sigma_max, nl->shell)) /
               fabs(rate);
    nl->drift = 0.999 * (0.25 * L[0] - nl->shell);
    nl->span = GR_NL_TILT / fabs(rate);
    nl->tref = nl->span;
    nl->lx = L[0];
    nl->built = malloc((size_t)n * sizeof *nl->built);
    nl->lap = calloc((size_t)n, sizeof *nl->lap);
    nl->expiry = calloc(2 * (size_t)n, sizeof *nl->expiry);
    if (!nl->built || !nl->lap || !nl->expiry) return GR_ERR_NOMEM;
    for (int32_t i = 0; i < n; i++) nl->built[i] = 0.0;
    return GR_OK;
}

void gr_nlist_free(gr_nlist *nl)
{
    free(nl->built);
    free(nl->lap);
    free(nl->expiry);
    free(nl->blocks);
    free(nl->centre);
    free(nl->rows);
    free(nl->near);
    free(nl->mark);
}

int gr_nlist_grow(gr_nlist *nl, int32_t n, const gr_sched *sched)
{
    const int32_t cap = 2 * nl->cap;
    int32_t *rows = cap > GR_NL_CAP_MAX ? NULL : gr_big_alloc((size_t)n * (size_t)cap * sizeof *rows);
    if (!rows) {
        nl->broken = 1;
        return GR_ERR_NOMEM;
    }
    for (int32_t i = 0; i < n; i++)
        memcpy(rows + (size_t)i * cap, nl->rows + (size_t)i * nl->cap,
               (size_t)sched[i].nn * sizeof *rows);
    free(nl->rows);
    nl->rows = rows;
    nl->cap = cap;
    return GR_OK;
}
