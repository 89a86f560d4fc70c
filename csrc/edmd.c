/* edmd.c -- construction, validation and inspection of an event-driven system, and the
 * dispatch to the kernels specialised for 2D and 3D (edmd_dim.h, included twice).
 *
 * How the engine keeps its per-event cost independent of N:
 *  - every particle carries its own clock: its record holds the position at time t_i
 *    and is advanced only when an event touches it;
 *  - the box is cut into cells at least one largest diameter wide; a particle looks for
 *    partners in its own and the adjacent cells only, and crossing into a new cell is an
 *    event that scans just the newly adjacent layer of cells; a bit per cell says which
 *    cells hold anyone, so scans skip the empty ones (most of them in a dilute gas);
 *  - each particle keeps one predicted collision (pair or wall) and one cell crossing; the
 *    queue holds the earlier of the two.  A predicted pair collision remembers the
 *    partner's collision counter and is found stale when popped if the partner collided
 *    since (lazy invalidation) -- then only that particle is rescanned;
 *  - the queue is a calendar queue (calendar.c): O(1) per key change, where a heap's
 *    O(log N) sift is a chain of cache misses at large N;
 *  - at large N what remains is memory latency: particles are renumbered in cell order
 *    now and then (reorder), the next event's particle and a pair's partner are
 *    prefetched, and the big arrays sit on huge pages where the OS offers them.
 *  - a few particles much larger than the rest (a tracer) would make every cell as wide
 *    as they are and every scan O(N); instead they stay out of the grid's lists: each
 *    small particle's scan also checks every big one, and a big one scans the block of
 *    cells within its reach, R = ceil((r_big + r_small_max) / w) cells each way, and on
 *    crossing a cell wall the newly reached layer of that block.
 *  - in a dense gas a scan's 27 cells hold ~25 particles, of which only the ~8 nearest
 *    can be hit before long.  There the engine can keep neighbour lists instead (Verlet
 *    lists as in Smallenburg's EDMD): particle i lists everyone whose list centre lies
 *    within r_i + r_j + 2 delta of its own, the centre being i's position when its list
 *    was last built; leaving the sphere of radius delta about it is i's structural event
 *    (in place of a cell crossing), which rebuilds i's list from the cells (that hold
 *    centres, not positions) and mends its neighbours' lists, which stay symmetric.  Two
 *    particles each within delta of their centres can only touch if listed, so
 *    predictions scan the list: contiguous indices whose records load in parallel,
 *    where a cell's linked list is a chain of dependent loads.
 * Invariant: for every pair of particles within reach (adjacent cells; a big particle's
 * block; a neighbour list), the earliest collision on their current straight lines is no
 * earlier than the queue key of one of the two. */
#define _DEFAULT_SOURCE         /* madvise (hugemem.h) */
#define _POSIX_C_SOURCE 200112L /* posix_memalign */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "collide.h"
#include "edmd.h"
#include "hugemem.h"
#include "calendar.h"

/* Every small particle's scan checks every big one, so only a few may be big (the same
 * limit as _BIG_MAX in granular/scene.py). */
#define GR_BIG_MAX 16

/* Everything an event reads and writes about one particle besides its position record,
 * in one cache line: at large N each separate array would be one more miss per event. */
typedef struct {
    double t_coll;   /* predicted pair or wall collision, +inf if none */
    double t_cross;  /* next cell crossing (lists: leaving the shell), +inf if none */
    double t_last;   /* time of this particle's last collision (TC model, collapse) */
    int64_t count;   /* this particle's collisions, pair and wall */
    int64_t pcount;  /* partner's collision counter when predicted */
    int32_t partner; /* >= 0: particle; -1: none; <= -2: wall -(2 + 2*axis + side) */
    int32_t last;    /* partner of the last collision (a wall as in `partner`), -1 none */
    int32_t c[3];    /* cell coordinates (the first dim used; lists: of the centre) */
    int8_t cross;    /* 2*axis + (1 if moving up), -1 none */
    int8_t streak;   /* consecutive collisions each within eps_t of the previous one,
                      * saturating (only "more than GR_COLLAPSE_STREAK" matters) */
    int16_t nn;      /* length of the neighbour list (list mode) */
} gr_event;
typedef char gr_event_fills_one_line[sizeof(gr_event) == 64 ? 1 : -1];

struct gr_edmd {
    gr_edmd_config cfg;
    int dim, stride;  /* stride = doubles per particle record: x[dim] v[dim] t r */
    int32_t n;
    double L[3];
    double *P;        /* n * stride, 64-byte aligned */
    double *mass;
    int64_t *image;   /* n * dim periodic image counters */
    gr_event *ev;
    gr_cq queue;
    int32_t *id_of;   /* the caller's index of each internal particle (see reorder) */
    uint8_t *is_big;  /* 1 for a particle kept out of the cell lists */
    int32_t n_big;
    int32_t big[GR_BIG_MAX]; /* the big particles' internal indices */
    double r_small;   /* largest radius among the particles in the cell lists */
    void *scratch;    /* room for n records or n events, for reordering */
    int64_t next_reorder;

    /* cell grid */
    int nc[3];
    double w[3];
    int32_t ncells;
    int32_t *head, *next, *prev;
    int prefetch_heads;   /* the heads take more than GR_HEADS_CACHED bytes */
    /* One bit per cell, set iff the cell holds a particle.  Most cells of a dilute gas
     * are empty (cells are one diameter wide: ~8 per particle at packing 0.065), and at
     * large N the head array is far out of cache; the bits are 32 times smaller, so a
     * scan learns which of its 27 cells to visit from lines it mostly has at hand. */
    uint64_t *occ;

    /* neighbour lists (list mode, shell > 0; see the top of the file) */
    double shell;         /* delta, absolute; 0: cell-crossing mode */
    double exit2;         /* squared distance from the centre that ends a list's life */
    double *centre;       /* n * (dim + 1): each list centre and the particle's radius */
    /* n * nl_cap: i's neighbours from nl[i * nl_cap] on, ev[i].nn of them, each as
     * (j << GR_NL_BITS) | image code: the shift that brings j next to i stays the same
     * until one of them rebuilds, so scans need no nearest-image arithmetic */
    int32_t *nl;
    int32_t nl_cap;
    int32_t *nl_near;     /* n: room for a rebuild's new neighbours */
    int nl_broken;        /* a list could not grow: lists are incomplete, no more events */
    double img[32][3];    /* image code -> shift, code = sum over axes of (s_a + 1) 3^a */
    int32_t *nb_cell[3];  /* [axis][3*c + d+1]: neighbouring coordinate or -1 */
    double *nb_shift[3];  /* [axis][3*c + d+1]: image shift in box lengths' units */
    /* Linear index offsets of the adjacent cells of a cell away from the box edge (the
     * common case, which then needs no wrapping and no image shifts): all of them, and
     * the layer newly adjacent after a crossing along axis a in direction up/down. */
    int32_t off_all[27];
    int32_t off_layer[6][9];

    /* time and counters */
    double t, eps_t;
    double t_prev_event;
    int64_t same_instant;
    int64_t events, pair, wall, crossings, invalid, elastic_tc;
    double virial, wall_impulse, kinetic;
    double kinetic_time; /* integral of the total kinetic energy over time, for the pressure */
};

/* Consecutive collisions of one particle, each within eps_t of the previous, that are
 * taken as inelastic collapse.  A gas never comes near this by chance (each such
 * collision has a probability of order 1e-9).  A fast collapse completes in floating
 * point within few collisions: three disks in a line with xi = 0.05 (< 7 - 4 sqrt 3)
 * make 46 collisions, of which only 16 to 19 in a row fall within eps_t, so the
 * threshold must stay well below that. */
#define GR_COLLAPSE_STREAK 10
#define GR_STR(x) #x
#define GR_XSTR(x) GR_STR(x)

/* Large systems renumber their particles in cell order every GR_REORDER_EVENTS_PER_N * N
 * events, so that particles in adjacent cells are close in memory; small ones fit in
 * the cache anyway and skip it. */
#define GR_REORDER_MIN_N 4096
#define GR_REORDER_EVENTS_PER_N 16

/* Cell heads beyond this many bytes are taken as out of cache, and scans ask for the
 * occupied cells' heads ahead.  In cache the extra loop only costs (cachegrind, 2D
 * N = 1e4 with 196 kB of heads: 0.4 fewer mispredicted branches per event without it);
 * at 3D N = 1e5 (3.2 MB) it saves time. */
#define GR_HEADS_CACHED ((size_t)1 << 20)

/* Prefetching: at large N the particle an event touches is a cache miss in every
 * per-particle array; asking for them one event ahead (and for a pair's partner before
 * the first of them is used) overlaps those misses with useful work.  A hint only:
 * compilers without the builtin lose speed, not correctness. */
#if defined(__GNUC__) || defined(__clang__)
#define GR_PREFETCH(p) __builtin_prefetch(p)
#else
#define GR_PREFETCH(p) ((void)(p))
#endif

/* Move the system clock forward to t, integrating the kinetic energy on the way (it
 * changes only at collisions, so the integral is exact up to rounding). */
static inline void set_clock(gr_edmd *s, double t)
{
    if (t > s->t) {
        s->kinetic_time += s->kinetic * (t - s->t);
        s->t = t;
    }
}

static inline double *rec(const gr_edmd *s, int32_t i) { return s->P + (size_t)i * s->stride; }

/* The linear index of the cell at coordinates c (cell_of in edmd_dim.h, for any dim). */
static inline int32_t cell_index(const gr_edmd *s, const int32_t *c)
{
    int32_t k = 0;
    for (int a = s->dim - 1; a >= 0; a--) k = k * s->nc[a] + c[a];
    return k;
}

/* The separation d along an axis of periodic length L seen through the nearest image
 * (|d| < 3L/2, as between particles in the box). */
static inline double nearest_image(double d, double L)
{
    return d > 0.5 * L ? d - L : d < -0.5 * L ? d + L : d;
}

/* The caller's index of internal particle i (negative codes pass through). */
static inline int64_t uid(const gr_edmd *s, int32_t i) { return i < 0 ? -1 : s->id_of[i]; }

static inline int cell_occupied(const gr_edmd *s, int32_t c)
{
    return (int)((s->occ[c >> 6] >> (c & 63)) & 1);
}

static inline void cell_insert(gr_edmd *s, int32_t i, int32_t c)
{
    s->prev[i] = -1;
    s->next[i] = s->head[c];
    if (s->head[c] >= 0) s->prev[s->head[c]] = i;
    else s->occ[c >> 6] |= (uint64_t)1 << (c & 63);
    s->head[c] = i;
}

static inline void cell_remove(gr_edmd *s, int32_t i, int32_t c)
{
    if (s->prev[i] >= 0) s->next[s->prev[i]] = s->next[i];
    else if ((s->head[c] = s->next[i]) < 0) s->occ[c >> 6] &= ~((uint64_t)1 << (c & 63));
    if (s->next[i] >= 0) s->prev[s->next[i]] = s->prev[i];
}

static int reorder(gr_edmd *s);

/* Neighbour lists: rows of nl_cap entries, doubled when one overflows (rarely with the
 * automatic shell of 0.25 diameters: a close-packed crystal has 18 neighbours within
 * 1.5 diameters in 3D, 6 in 2D; a wide particle among small ones has more).  An entry
 * keeps the image code in its low GR_NL_BITS bits, so list mode needs n < 2^26. */
#define GR_NL_CAP_MAX 16384
#define GR_NL_BITS 5
#define GR_NL_MAX_N ((int64_t)1 << (31 - GR_NL_BITS))

static int nl_grow(gr_edmd *s)
{
    const int32_t cap = 2 * s->nl_cap;
    int32_t *nl = cap > GR_NL_CAP_MAX ? NULL : gr_big_alloc((size_t)s->n * (size_t)cap * sizeof *nl);
    if (!nl) {
        s->nl_broken = 1;
        return GR_ERR_NOMEM;
    }
    for (int32_t i = 0; i < s->n; i++)
        memcpy(nl + (size_t)i * cap, s->nl + (size_t)i * s->nl_cap,
               (size_t)s->ev[i].nn * sizeof *nl);
    free(s->nl);
    s->nl = nl;
    s->nl_cap = cap;
    return GR_OK;
}

/* List i and j as neighbours of each other, j seen from i through image `code`. */
static int nl_link(gr_edmd *s, int32_t i, int32_t j, int32_t code, gr_error *err)
{
    if (s->ev[i].nn == s->nl_cap || s->ev[j].nn == s->nl_cap) {
        int status = nl_grow(s);
        if (status != GR_OK) {
            gr_error_set(err, status, uid(s, i), -1, s->t, (double)s->nl_cap,
                         "a neighbour list could not grow (out of memory, or past "
                         GR_XSTR(GR_NL_CAP_MAX) " entries); the system cannot go on");
            return status;
        }
    }
    const int32_t opposite = (s->dim == 3 ? 26 : 8) - code;
    s->nl[(size_t)i * s->nl_cap + s->ev[i].nn++] = (j << GR_NL_BITS) | code;
    s->nl[(size_t)j * s->nl_cap + s->ev[j].nn++] = (i << GR_NL_BITS) | opposite;
    return GR_OK;
}

/* Take i off j's list (order within a list does not matter). */
static inline void nl_unlink(gr_edmd *s, int32_t j, int32_t i)
{
    int32_t *row = s->nl + (size_t)j * s->nl_cap;
    const int last = s->ev[j].nn - 1;
    for (int k = 0; k <= last; k++)
        if (row[k] >> GR_NL_BITS == i) {
            row[k] = row[last];
            s->ev[j].nn--;
            return;
        }
}

#define DIM 2
#define FN(name) name##_2d
#include "edmd_dim.h"
#undef DIM
#undef FN
#define DIM 3
#define FN(name) name##_3d
#include "edmd_dim.h"
#undef DIM
#undef FN

void gr_edmd_free(gr_edmd *s)
{
    if (!s) return;
    free(s->P);
    free(s->mass);
    free(s->image);
    free(s->ev);
    free(s->id_of);
    free(s->is_big);
    free(s->scratch);
    gr_cq_free(&s->queue);
    free(s->head);
    free(s->occ);
    free(s->next);
    free(s->prev);
    free(s->centre);
    free(s->nl);
    free(s->nl_near);
    for (int a = 0; a < 3; a++) {
        free(s->nb_cell[a]);
        free(s->nb_shift[a]);
    }
    free(s);
}

static int cmp_radius(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Cells per axis: at least cell_factor * sigma wide, and not more cells than a few per
 * particle (a dilute gas in a big box must not allocate a huge empty grid; wider cells
 * are always correct, only slower to scan). */
static double grid_dims(const gr_edmd *s, double sigma, double k[3])
{
    const int d = s->dim;
    const double wmin = sigma * s->cfg.cell_factor;
    const double cap = 8.0 * (double)s->n + 64.0;
    double total = 1.0;
    k[0] = k[1] = k[2] = 1.0;
    for (int a = 0; a < d; a++) {
        k[a] = floor(s->L[a] / wmin);
        if (!(k[a] >= 1.0)) k[a] = 1.0;
        if (k[a] > 1e9) k[a] = 1e9;
        total *= k[a];
    }
    /* Fewer, wider cells until the grid fits the cap: each pass shrinks the total by
     * about total / cap, and k = 1 on every axis always fits. */
    while (total > cap) {
        double f = pow(total / cap, 1.0 / d);
        total = 1.0;
        for (int a = 0; a < d; a++) {
            k[a] = floor(k[a] / f);
            if (k[a] < 1.0) k[a] = 1.0;
            total *= k[a];
        }
    }
    return total;
}

/* Which particles stay out of the grid: those wider than big_ratio times the median
 * diameter, if there are at most GR_BIG_MAX of them and the grid of the others is fine
 * enough that a big particle's block of 2 R + 1 cells, plus a cell, is less than the box
 * on every axis: a periodic block then never meets itself, and any particle in it is
 * less than half a box away, so the nearest image is the one within reach.
 * Sets is_big, big, n_big and r_small.  Returns 0 or GR_ERR_NOMEM. */
static int choose_big(gr_edmd *s, const double *radius)
{
    const int32_t n = s->n;
    double rmax = 0.0;
    for (int32_t i = 0; i < n; i++) rmax = radius[i] > rmax ? radius[i] : rmax;
    s->r_small = rmax;
    s->n_big = 0;
    if (!(s->cfg.big_ratio < INFINITY) || n < 2) return GR_OK;
    double *sorted = malloc((size_t)n * sizeof *sorted);
    if (!sorted) return GR_ERR_NOMEM;
    memcpy(sorted, radius, (size_t)n * sizeof *sorted);
    qsort(sorted, (size_t)n, sizeof *sorted, cmp_radius);
    const double cut = s->cfg.big_ratio * sorted[n / 2];
    int32_t count = 0;
    double r_small = 0.0;
    for (int32_t i = 0; i < n; i++) {
        if (sorted[i] > cut) count++;
        else r_small = sorted[i];
    }
    free(sorted);
    if (count == 0 || count > GR_BIG_MAX) return GR_OK;
    double k[3];
    grid_dims(s, 2.0 * r_small, k);
    for (int a = 0; a < s->dim; a++) {
        double reach = ceil((rmax + r_small) / (s->L[a] / k[a]));
        if (!(2.0 * reach + 3.0 <= k[a])) return GR_OK;
    }
    for (int32_t i = 0; i < n; i++)
        if (radius[i] > cut) {
            s->is_big[i] = 1;
            s->big[s->n_big++] = i;
        }
    s->r_small = r_small;
    return GR_OK;
}

static int build_grid(gr_edmd *s, double sigma_max, gr_error *err)
{
    const int d = s->dim;
    double k[3];
    double total = grid_dims(s, sigma_max, k);
    if (total > (double)(INT32_MAX / 2)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, total, "too many cells for the particle count");
        return GR_ERR_VALUE;
    }
    s->ncells = 1;
    for (int a = 0; a < 3; a++) {
        if (a >= d) { s->nc[a] = 1; s->w[a] = 1.0; continue; }
        s->nc[a] = (int)k[a];
        s->w[a] = s->L[a] / s->nc[a];
        s->ncells *= s->nc[a];
    }
    s->head = gr_big_alloc((size_t)s->ncells * sizeof *s->head);
    s->prefetch_heads = (size_t)s->ncells * sizeof *s->head > GR_HEADS_CACHED;
    s->occ = calloc(((size_t)s->ncells + 63) / 64, sizeof *s->occ);
    if (!s->head || !s->occ) return GR_ERR_NOMEM;
    for (int32_t c = 0; c < s->ncells; c++) s->head[c] = -1;
    int k_all = 0, k_layer[6] = {0, 0, 0, 0, 0, 0};
    for (int d2 = (d == 3 ? -1 : 0); d2 <= (d == 3 ? 1 : 0); d2++)
        for (int d1 = -1; d1 <= 1; d1++)
            for (int d0 = -1; d0 <= 1; d0++) {
                int32_t off = d0 + s->nc[0] * (d1 + s->nc[1] * d2);
                int dd[3] = {d0, d1, d2};
                s->off_all[k_all++] = off;
                for (int a = 0; a < d; a++)
                    if (dd[a] != 0) {
                        int layer = 2 * a + (dd[a] > 0);
                        s->off_layer[layer][k_layer[layer]++] = off;
                    }
            }
    for (int a = 0; a < d; a++) {
        int m = s->nc[a];
        s->nb_cell[a] = malloc((size_t)3 * m * sizeof(int32_t));
        s->nb_shift[a] = malloc((size_t)3 * m * sizeof(double));
        if (!s->nb_cell[a] || !s->nb_shift[a]) return GR_ERR_NOMEM;
        for (int c = 0; c < m; c++) {
            for (int dd = -1; dd <= 1; dd++) {
                int q = c + dd;
                double shift = 0.0;
                if (q < 0 || q >= m) {
                    if (!s->cfg.periodic) { q = -1; }
                    else if (q < 0) { q += m; shift = -s->L[a]; }
                    else { q -= m; shift = s->L[a]; }
                }
                s->nb_cell[a][3 * c + dd + 1] = q;
                s->nb_shift[a][3 * c + dd + 1] = shift;
            }
        }
    }
    return GR_OK;
}

int gr_edmd_new(gr_edmd **out, const gr_edmd_config *cfg, const double *pos,
                const double *vel, const double *radius, const double *mass, gr_error *err)
{
    *out = NULL;
    const int d = cfg->dim;
    if (d != 2 && d != 3) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, d, "dim must be 2 or 3");
        return GR_ERR_VALUE;
    }
    if (cfg->n < 1 || cfg->n > INT32_MAX / 2) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, (double)cfg->n,
                     "number of particles must be between 1 and 2^30");
        return GR_ERR_VALUE;
    }
    if (!(cfg->restitution >= 0.0 && cfg->restitution <= 1.0)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->restitution,
                     "restitution must lie in [0, 1]");
        return GR_ERR_VALUE;
    }
    if (!(cfg->wall_restitution > 0.0 && isfinite(cfg->wall_restitution))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->wall_restitution,
                     "wall restitution must be positive and finite");
        return GR_ERR_VALUE;
    }
    if (!(cfg->contact_duration >= 0.0 && isfinite(cfg->contact_duration))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->contact_duration,
                     "contact duration must be finite and >= 0");
        return GR_ERR_VALUE;
    }
    if (!(cfg->big_ratio >= 1.0)) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->big_ratio, "big_ratio must be >= 1 (inf: none)");
        return GR_ERR_VALUE;
    }
    if (!(cfg->cell_factor >= 1.0 && isfinite(cfg->cell_factor))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->cell_factor,
                     "cell_factor must be >= 1");
        return GR_ERR_VALUE;
    }
    /* a shell thinner than this rebuilds lists every few hundredths of a diameter
     * travelled, and its rounding margin (1e-9 of it) nears that of the coordinates */
    if (!(cfg->shell == 0.0 || (cfg->shell >= 0.01 && isfinite(cfg->shell)))) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, cfg->shell,
                     "shell must be 0 (cells) or finite and at least 0.01 (largest diameters)");
        return GR_ERR_VALUE;
    }
    const int32_t n = (int32_t)cfg->n;
    double sigma_max = 0.0, sigma_min = INFINITY;
    for (int32_t i = 0; i < n; i++) {
        if (!(radius[i] > 0.0 && isfinite(radius[i]))) {
            gr_error_set(err, GR_ERR_VALUE, i, -1, NAN, radius[i], "radii must be positive and finite");
            return GR_ERR_VALUE;
        }
        if (!(mass[i] > 0.0 && isfinite(mass[i]))) {
            gr_error_set(err, GR_ERR_VALUE, i, -1, NAN, mass[i], "masses must be positive and finite");
            return GR_ERR_VALUE;
        }
        for (int a = 0; a < d; a++) {
            if (!isfinite(pos[i * d + a]) || !isfinite(vel[i * d + a])) {
                gr_error_set(err, GR_ERR_NONFINITE, i, -1, NAN, NAN, "in the initial positions or velocities");
                return GR_ERR_NONFINITE;
            }
        }
        if (2.0 * radius[i] > sigma_max) sigma_max = 2.0 * radius[i];
        if (2.0 * radius[i] < sigma_min) sigma_min = 2.0 * radius[i];
    }
    for (int a = 0; a < d; a++) {
        double L = cfg->hi[a] - cfg->lo[a];
        if (!(L > 0.0 && isfinite(L) && isfinite(cfg->lo[a]))) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, L, "the box needs lower < upper, finite, on every axis");
            return GR_ERR_VALUE;
        }
        if (cfg->periodic && !(L > 2.0 * sigma_max)) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, L,
                         "a periodic box must be more than two largest diameters wide on every axis");
            return GR_ERR_VALUE;
        }
        if (!cfg->periodic && !(L >= sigma_max)) {
            gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, L,
                         "the box is narrower than the largest particle");
            return GR_ERR_VALUE;
        }
    }
    for (int32_t i = 0; i < n; i++) {
        for (int a = 0; a < d; a++) {
            double x = pos[i * d + a];
            double lo = cfg->lo[a], hi = cfg->hi[a];
            /* walls: the whole disk inside (a relative 1e-12 of slack for rounding);
             * periodic: the centre inside. */
            double slack = 1e-12 * (hi - lo);
            int out = cfg->periodic ? (x < lo || x > hi)
                                    : (x - radius[i] < lo - slack || x + radius[i] > hi + slack);
            if (out) {
                gr_error_set(err, GR_ERR_OUTSIDE, i, -1, NAN, x,
                             cfg->periodic ? "its centre is outside [lower, upper]"
                                           : "it crosses a wall");
                return GR_ERR_OUTSIDE;
            }
        }
    }

    gr_edmd *s = calloc(1, sizeof *s);
    if (!s) return GR_ERR_NOMEM;
    s->cfg = *cfg;
    s->dim = d;
    s->stride = 2 * d + 2;
    s->n = n;
    for (int a = 0; a < 3; a++) s->L[a] = a < d ? cfg->hi[a] - cfg->lo[a] : 1.0;
    size_t bytes = ((size_t)n * s->stride * sizeof(double) + 63) / 64 * 64;
    s->P = gr_big_alloc(bytes); /* records on cache-line boundaries: a 3D record is one line */
    s->mass = gr_big_alloc((size_t)n * sizeof *s->mass);
    s->image = calloc((size_t)n * d, sizeof *s->image);
    s->ev = gr_big_alloc((size_t)n * sizeof *s->ev);
    s->next = gr_big_alloc((size_t)n * sizeof *s->next);
    s->prev = gr_big_alloc((size_t)n * sizeof *s->prev);
    s->id_of = malloc((size_t)n * sizeof *s->id_of);
    s->is_big = calloc((size_t)n, sizeof *s->is_big);
    const size_t per = (size_t)s->stride * sizeof(double) > sizeof(gr_event)
                           ? (size_t)s->stride * sizeof(double) : sizeof(gr_event);
    if (n >= GR_REORDER_MIN_N) s->scratch = malloc((size_t)n * per);
    int status = GR_OK;
    if (!s->P || !s->mass || !s->image || !s->ev || !s->next || !s->prev ||
        !s->id_of || !s->is_big || (n >= GR_REORDER_MIN_N && !s->scratch))
        status = GR_ERR_NOMEM;
    if (status == GR_OK) status = gr_cq_init(&s->queue, n);
    /* List mode, unless the box is too small for the shell: every pair within reach
     * must be less than half a box apart for the nearest image to be the one that
     * collides (list centres within sigma + 2 delta, positions within delta of them). */
    s->shell = cfg->shell * sigma_max;
    for (int a = 0; a < d; a++)
        if (cfg->periodic && !(s->L[a] > 2.0 * (sigma_max + 4.0 * s->shell))) s->shell = 0.0;
    if (n >= GR_NL_MAX_N) s->shell = 0.0;
    if (s->shell > 0.0) {
        /* leave a hair early: two particles each within delta (1 - 1e-9) of centres more
         * than sigma + 2 delta apart stay apart by more than rounding */
        s->exit2 = s->shell * (1.0 - 1e-9) * s->shell * (1.0 - 1e-9);
        s->r_small = 0.5 * sigma_max; /* no big particles */
        s->nl_cap = d == 3 ? 32 : 16;
        s->centre = gr_big_alloc((size_t)n * (d + 1) * sizeof *s->centre);
        s->nl = gr_big_alloc((size_t)n * s->nl_cap * sizeof *s->nl);
        s->nl_near = malloc((size_t)n * sizeof *s->nl_near);
        if (status == GR_OK && (!s->centre || !s->nl || !s->nl_near)) status = GR_ERR_NOMEM;
        for (int code = 0; code < 32; code++)
            for (int a = 0, k = code; a < 3; a++, k /= 3)
                s->img[code][a] = a < d ? (double)(k % 3 - 1) * s->L[a] : 0.0;
    } else if (status == GR_OK) {
        status = choose_big(s, radius);
    }
    if (status == GR_OK) status = build_grid(s, 2.0 * s->r_small + 2.0 * s->shell, err);
    if (status != GR_OK) {
        gr_edmd_free(s);
        return status;
    }

    double v2m = 0.0, msum = 0.0;
    for (int32_t i = 0; i < n; i++) {
        double *p = rec(s, i);
        for (int a = 0; a < d; a++) {
            p[a] = pos[i * d + a];
            p[d + a] = vel[i * d + a];
            v2m += mass[i] * vel[i * d + a] * vel[i * d + a];
        }
        p[2 * d] = 0.0;
        p[2 * d + 1] = radius[i];
        s->mass[i] = mass[i];
        msum += mass[i];
        s->ev[i] = (gr_event){.t_coll = INFINITY, .t_cross = INFINITY, .t_last = -INFINITY,
                              .count = 0, .pcount = 0, .partner = -1, .last = -1, .cross = -1,
                              .streak = 0};
        s->id_of[i] = i;
    }
    s->kinetic = 0.5 * v2m;
    /* The collapse test's notion of "one instant": a billionth of the time a particle
     * of typical speed needs to cross the smallest diameter. */
    double vrms = sqrt(v2m / msum);
    s->eps_t = vrms > 0.0 ? 1e-9 * sigma_min / vrms : 0.0;
    s->t_prev_event = -INFINITY;

    status = d == 2 ? setup_2d(s, err) : setup_3d(s, err);
    if (status != GR_OK) {
        gr_edmd_free(s);
        return status;
    }
    *out = s;
    return GR_OK;
}

/* Renumber the particles in the order of their cells (a counting sort, O(N + cells)),
 * permuting every per-particle array and remapping every stored particle index: event
 * partners, the event queue, the cell lists.  Only the numbering changes -- positions,
 * velocities, predictions and the order of events stay exactly as they were. */
static int reorder(gr_edmd *s)
{
    const int32_t n = s->n;
    const int d = s->dim;
    if (!s->scratch) return GR_OK;
    int32_t *start = calloc((size_t)s->ncells + 1, sizeof *start);
    int32_t *newpos = malloc((size_t)n * sizeof *newpos);
    int32_t *nl = s->shell > 0.0 ? gr_big_alloc((size_t)n * s->nl_cap * sizeof *nl) : NULL;
    if (!start || !newpos || (s->shell > 0.0 && !nl)) {
        free(start);
        free(newpos);
        free(nl);
        return GR_ERR_NOMEM;
    }
    for (int32_t i = 0; i < n; i++) {
        const int32_t c = cell_index(s, s->ev[i].c);
        newpos[i] = c; /* the cell, for now */
        start[c + 1]++;
    }
    for (int32_t c = 0; c < s->ncells; c++) start[c + 1] += start[c];
    for (int32_t i = 0; i < n; i++) newpos[i] = start[newpos[i]]++;
    free(start);

#define PERMUTE(arr, type, width)                                                       \
    do {                                                                                \
        type *tmp = (type *)s->scratch;                                                 \
        for (int32_t i = 0; i < n; i++)                                                 \
            memcpy(tmp + (size_t)newpos[i] * (width), (arr) + (size_t)i * (width),      \
                   (width) * sizeof(type));                                             \
        memcpy((arr), tmp, (size_t)n * (width) * sizeof(type));                          \
    } while (0)
    PERMUTE(s->P, double, (size_t)s->stride);
    PERMUTE(s->mass, double, 1);
    PERMUTE(s->image, int64_t, (size_t)d);
    PERMUTE(s->id_of, int32_t, 1);
    PERMUTE(s->is_big, uint8_t, 1);
    if (s->shell > 0.0) PERMUTE(s->centre, double, (size_t)d + 1);
#undef PERMUTE
    if (nl) {
        for (int32_t i = 0; i < n; i++) {
            const int32_t *from = s->nl + (size_t)i * s->nl_cap;
            int32_t *to = nl + (size_t)newpos[i] * s->nl_cap;
            for (int k = 0; k < s->ev[i].nn; k++) {
                const int32_t code = from[k] & ((1 << GR_NL_BITS) - 1);
                to[k] = (newpos[from[k] >> GR_NL_BITS] << GR_NL_BITS) | code;
            }
        }
        free(s->nl);
        s->nl = nl;
    }
    for (int32_t b = 0; b < s->n_big; b++) s->big[b] = newpos[s->big[b]];
    {
        gr_event *tmp = s->scratch;
        for (int32_t i = 0; i < n; i++) {
            gr_event e = s->ev[i];
            if (e.partner >= 0) e.partner = newpos[e.partner];
            if (e.last >= 0) e.last = newpos[e.last];
            tmp[newpos[i]] = e;
        }
        memcpy(s->ev, tmp, (size_t)n * sizeof *tmp);
    }
    gr_cq_renumber(&s->queue, newpos);
    free(newpos);
    for (int32_t c = 0; c < s->ncells; c++) s->head[c] = -1;
    memset(s->occ, 0, ((size_t)s->ncells + 63) / 64 * sizeof *s->occ);
    for (int32_t i = n - 1; i >= 0; i--) { /* lists in increasing index order */
        if (s->is_big[i]) continue;
        cell_insert(s, i, cell_index(s, s->ev[i].c));
    }
    s->next_reorder = s->events + (int64_t)GR_REORDER_EVENTS_PER_N * n;
    return GR_OK;
}

int gr_edmd_advance(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err)
{
    if (s->nl_broken) {
        gr_error_set(err, GR_ERR_NOMEM, -1, -1, s->t, (double)s->nl_cap,
                     "a neighbour list could not grow earlier; the system cannot go on");
        return GR_ERR_NOMEM;
    }
    return s->dim == 2 ? advance_2d(s, stop, smp, err) : advance_3d(s, stop, smp, err);
}

void gr_edmd_state(const gr_edmd *s, double *pos, double *vel, int64_t *image)
{
    const int d = s->dim;
    for (int32_t i = 0; i < s->n; i++) {
        const double *p = rec(s, i);
        double dt = s->t - p[2 * d];
        for (int a = 0; a < d; a++) {
            double x = p[a] + p[d + a] * dt;
            int64_t img = s->image[(size_t)i * d + a];
            size_t out = (size_t)s->id_of[i] * d + a;
            if (s->cfg.periodic) {
                /* a crossing due exactly now may not have been processed yet */
                if (x >= s->cfg.hi[a]) { x -= s->L[a]; img++; }
                else if (x < s->cfg.lo[a]) { x += s->L[a]; img--; }
            }
            if (pos) pos[out] = x;
            if (vel) vel[out] = p[d + a];
            if (image) image[out] = img;
        }
    }
}

void gr_edmd_get_counters(const gr_edmd *s, gr_edmd_counters *c)
{
    c->t = s->t;
    c->events = s->events;
    c->pair = s->pair;
    c->wall = s->wall;
    c->crossings = s->crossings;
    c->invalid = s->invalid;
    c->elastic_tc = s->elastic_tc;
    c->virial = s->virial;
    c->wall_impulse = s->wall_impulse;
    c->kinetic_time = s->kinetic_time;
    double k = 0.0;
    for (int32_t i = 0; i < s->n; i++) {
        const double *p = rec(s, i);
        double v2 = 0.0;
        for (int a = 0; a < s->dim; a++) v2 += p[s->dim + a] * p[s->dim + a];
        k += 0.5 * s->mass[i] * v2;
    }
    c->kinetic = k;
    for (int a = 0; a < 3; a++) c->ncell[a] = s->nc[a];
    c->shell = s->shell > 0.0 ? s->cfg.shell : 0.0;
}
