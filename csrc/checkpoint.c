/* checkpoint.c -- saving an engine's state to bytes and restoring it (checkpoint.h).
 *
 * One function, transfer(), lists everything a checkpoint holds in order, and is used in
 * both directions, so what is written and what is read cannot drift apart.  Reading
 * goes into freshly allocated arrays, which are checked (check_state) before they
 * replace the engine's own: a bad buffer leaves the engine untouched. */
#define _DEFAULT_SOURCE         /* madvise (hugemem.h) */
#define _POSIX_C_SOURCE 200112L /* posix_memalign */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "checkpoint.h"
#include "drive.h"
#include "engine.h"
#include "hugemem.h"
#include "le_cells.h"
#include "scene_params.h"

static const char magic[8] = {'G', 'R', 'E', 'D', 'M', 'D', 'C', 'K'};
#define GR_BYTE_ORDER_MARK 0x01020304u

/* FNV-1a over the numbers that describe the layout. */
static uint64_t mix(uint64_t h, uint64_t x)
{
    for (int k = 0; k < 8; k++) {
        h ^= (x >> (8 * k)) & 0xff;
        h *= 0x100000001b3ULL;
    }
    return h;
}

uint64_t gr_checkpoint_layout(void)
{
    const uint64_t parts[] = {
        GR_CHECKPOINT_VERSION, sizeof(void *), sizeof(double), sizeof(gr_edmd),
        sizeof(gr_edmd_config), sizeof(gr_cq), sizeof(gr_cells), sizeof(gr_nlist),
        sizeof(gr_big), GR_BIG_MAX, GR_NL_BITS, GR_NL_CAP_MAX,
        sizeof(gr_sched), offsetof(gr_sched, t_coll), offsetof(gr_sched, t_cross),
        offsetof(gr_sched, t_last), offsetof(gr_sched, count), offsetof(gr_sched, pcount),
        offsetof(gr_sched, partner), offsetof(gr_sched, last), offsetof(gr_sched, c),
        offsetof(gr_sched, cross), offsetof(gr_sched, streak), offsetof(gr_sched, nn),
        sizeof(gr_cq_item), offsetof(gr_cq_item, t), offsetof(gr_cq_item, next),
        offsetof(gr_cq_item, prev),
    };
    uint64_t h = 0xcbf29ce484222325ULL;
    for (size_t k = 0; k < sizeof parts / sizeof parts[0]; k++) h = mix(h, parts[k]);
    return h;
}

/* ---- a cursor over the buffer: writing (out != NULL), reading (in != NULL), or only
 * counting bytes (neither) ---- */

typedef struct {
    unsigned char *out;
    const unsigned char *in;
    size_t size, at;
    int bad;          /* a read past the end */
    int law_differs;  /* a restitution law read differs from the engine's */
} cursor;

static void io(cursor *c, void *p, size_t bytes)
{
    if (c->in) {
        if (c->bad || bytes > c->size - c->at) {
            c->bad = 1;
            return;
        }
        memcpy(p, c->in + c->at, bytes);
    } else if (c->out) {
        memcpy(c->out + c->at, p, bytes);
    }
    c->at += bytes;
}

#define IO(c, x) io((c), &(x), sizeof(x))

static int same_double(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* A restitution law, in full (kind, numbers, table).  The engine's own law comes from
 * the scene it was built from; reading compares the file's with it number by number
 * (c->law_differs) and keeps the engine's, so a file cannot bring in another law, nor
 * size anything: a table is read only as long as the engine's. */
static void io_law(cursor *c, const gr_law *mine)
{
    gr_law l = *mine;
    IO(c, l.kind);
    IO(c, l.scale);
    IO(c, l.v_max);
    IO(c, l.count);
    if (c->in && !c->bad &&
        (l.kind != mine->kind || !same_double(l.scale, mine->scale) ||
         !same_double(l.v_max, mine->v_max) || l.count != mine->count))
        c->law_differs = 1;
    if (c->bad || c->law_differs || mine->kind != GR_LAW_TABLE) return;
    for (int side = 0; side < 2; side++) {
        const double *x = side ? mine->values : mine->speeds;
        for (int64_t k = 0; k < mine->count; k++) {
            double v = x[k];
            IO(c, v);
            if (c->bad) return;
            if (c->in && !same_double(v, x[k])) {
                c->law_differs = 1;
                return;
            }
        }
    }
}

/* The header: what the sizes of the arrays that follow depend on. */
typedef struct {
    char magic[8];
    uint32_t version, byte_order;
    uint64_t layout;
    uint64_t total;      /* bytes of the whole checkpoint */
    int64_t n;
    int32_t dim, stride, lists, nb, ncells, nc[3], cap, big_n;
    int32_t spin;        /* 1: rough particles' spins follow the masses */
} header;

static header header_of(const gr_edmd *s, size_t total)
{
    header h;
    memset(&h, 0, sizeof h);
    memcpy(h.magic, magic, sizeof magic);
    h.version = GR_CHECKPOINT_VERSION;
    h.byte_order = GR_BYTE_ORDER_MARK;
    h.layout = gr_checkpoint_layout();
    h.total = total;
    h.n = s->n;
    h.dim = s->dim;
    h.stride = GR_STRIDE(s->dim);
    h.lists = s->nl.shell > 0.0;
    h.nb = s->queue.nb;
    h.ncells = s->cells.ncells;
    for (int a = 0; a < 3; a++) h.nc[a] = s->cells.nc[a];
    h.cap = s->nl.cap;
    h.big_n = s->big.n;
    h.spin = s->spin != NULL;
    return h;
}

static void io_header(cursor *c, header *h)
{
    io(c, h->magic, sizeof h->magic);
    IO(c, h->version);
    IO(c, h->byte_order);
    IO(c, h->layout);
    IO(c, h->total);
    IO(c, h->n);
    IO(c, h->dim);
    IO(c, h->stride);
    IO(c, h->lists);
    IO(c, h->nb);
    IO(c, h->ncells);
    io(c, h->nc, sizeof h->nc);
    IO(c, h->cap);
    IO(c, h->big_n);
    IO(c, h->spin);
}

/* Everything after the header, in order.  The arrays of s must be allocated for the
 * header's sizes.  Counts read on the way (the near heap's size, list lengths) are
 * checked before they size a transfer; the rest of the checking is check_state's. */
static void transfer(cursor *c, gr_edmd *s)
{
    const int32_t n = s->n;
    const int d = s->dim;
    gr_edmd_config *cfg = &s->cfg;
    IO(c, cfg->dim);
    IO(c, cfg->n);
    io(c, cfg->lo, sizeof cfg->lo);
    io(c, cfg->hi, sizeof cfg->hi);
    IO(c, cfg->periodic);
#define TRANSFER(field) IO(c, cfg->field);
    GR_SCENE_DOUBLES(TRANSFER)
#undef TRANSFER
    IO(c, cfg->cell_factor);
    IO(c, cfg->big_ratio);
    IO(c, cfg->shell);
    IO(c, cfg->stress);
    io_law(c, &cfg->law);
    io_law(c, &cfg->wall_law);
    io(c, cfg->gravity, sizeof cfg->gravity);
    IO(c, cfg->free_fall);
    if (c->law_differs) return; /* read: the rest is not this scene's */
    IO(c, cfg->vib.on); /* the vibrating wall: compared with the scene's in check_state */
    IO(c, cfg->vib.axis);
    IO(c, cfg->vib.side);
    IO(c, cfg->vib.waveform);
    IO(c, cfg->vib.amplitude);
    IO(c, cfg->vib.omega);
    IO(c, cfg->vib.phase);
    IO(c, s->wall_work);
    IO(c, s->collision_loss);

    IO(c, s->t);
    IO(c, s->eps_t);
    IO(c, s->t_prev_event);
    IO(c, s->same_instant);
    IO(c, s->events);
    IO(c, s->pair);
    IO(c, s->wall);
    IO(c, s->invalid);
    IO(c, s->elastic_tc);
    IO(c, s->law_clamped);
    IO(c, s->crossings);
    IO(c, s->shell_exits);
    IO(c, s->virial);
    IO(c, s->wall_impulse);
    IO(c, s->kinetic);
    IO(c, s->kinetic_time);
    IO(c, s->shear_work);
    io(c, s->st_coll, sizeof s->st_coll);
    io(c, s->st_kin, sizeof s->st_kin);
    io(c, s->st_kin_time, sizeof s->st_kin_time);
    IO(c, s->stress_t);
    io(c, s->momentum, sizeof s->momentum);
    IO(c, s->mass_total);
    IO(c, s->order.next);
    IO(c, s->nl.broken);
    IO(c, s->drive_next);
    IO(c, s->kicks);
    IO(c, s->drive_energy);

    io(c, s->P, (size_t)n * GR_STRIDE(s->dim) * sizeof *s->P);
    io(c, s->mass, (size_t)n * sizeof *s->mass);
    if (s->spin) io(c, s->spin, (size_t)n * GR_SPIN_DIM(d) * sizeof *s->spin);
    io(c, s->image, (size_t)n * d * sizeof *s->image);
    io(c, s->sched, (size_t)n * sizeof *s->sched);
    io(c, s->order.id_of, (size_t)n * sizeof *s->order.id_of);
    io(c, s->big.is_big, (size_t)n * sizeof *s->big.is_big);
    io(c, s->big.idx, (size_t)s->big.n * sizeof *s->big.idx);

    gr_cq *q = &s->queue;
    IO(c, q->t0);
    IO(c, q->inv_w);
    IO(c, q->cur);
    IO(c, q->over_from);
    IO(c, q->over);
    IO(c, q->n_list);
    IO(c, q->n_over);
    IO(c, q->n_near);
    IO(c, q->nan_id);
    IO(c, q->changes);
    IO(c, q->rebuild_at);
    for (int32_t id = 0; id < n; id++) { /* field by field: no padding bytes in the file */
        IO(c, q->item[id].t);
        IO(c, q->item[id].next);
        IO(c, q->item[id].prev);
    }
    io(c, q->head, (size_t)q->nb * sizeof *q->head);
    if (q->n_near < 0 || q->n_near > n) { /* read: not to size the loop below */
        c->bad = 1;
        return;
    }
    for (int32_t k = 0; k < q->n_near; k++) {
        IO(c, q->near[k].t);
        IO(c, q->near[k].id);
    }

    io(c, s->cells.head, (size_t)s->cells.ncells * sizeof *s->cells.head);
    io(c, s->cells.next, (size_t)n * sizeof *s->cells.next);

    if (s->nl.shell > 0.0) {
        io(c, s->nl.centre, (size_t)n * (d + 1) * sizeof *s->nl.centre);
        for (int32_t i = 0; i < n; i++) { /* only the entries in use */
            const int16_t nn = s->sched[i].nn;
            if (nn < 0 || nn > s->nl.cap) {
                c->bad = 1;
                return;
            }
            io(c, nl_row(&s->nl, i), (size_t)nn * sizeof(int32_t));
        }
        if (s->nl.built) { /* sheared */
            io(c, s->nl.built, (size_t)n * sizeof *s->nl.built);
            io(c, s->nl.lap, (size_t)n * sizeof *s->nl.lap);
            IO(c, s->nl.tref);
        }
    }
}

size_t gr_edmd_save_size(const gr_edmd *s)
{
    cursor c = {NULL, NULL, 0, 0, 0, 0};
    header h = header_of(s, 0);
    io_header(&c, &h);
    transfer(&c, (gr_edmd *)s); /* counting only: s is not written */
    return c.at;
}

int gr_edmd_save(const gr_edmd *s, unsigned char *buf, size_t size)
{
    const size_t total = gr_edmd_save_size(s);
    if (size < total) return GR_ERR_VALUE;
    cursor c = {buf, NULL, size, 0, 0, 0};
    header h = header_of(s, total);
    io_header(&c, &h);
    transfer(&c, (gr_edmd *)s); /* writing: s is only read */
    return GR_OK;
}

/* ---- restoring ---- */

/* Whether an engine with n particles in list mode could have grown its rows to cap
 * entries (nlist.c): from GR_NL_CAP_START by doublings, up to GR_NL_CAP_MAX, each one
 * made when a row of cap / 2 entries needed one more -- and a row lists each other
 * particle at most once (the box is more than twice the lists' reach wide, build.c), so
 * cap / 2 < n - 1.  The rows are n * cap int32 allocated before anything else is read:
 * no more than the engine itself could have allocated. */
static int cap_reachable(int32_t cap, int dim, int64_t n)
{
    const int32_t start = GR_NL_CAP_START(dim);
    if (cap < start || cap > GR_NL_CAP_MAX || cap % start != 0) return 0;
    const int32_t doublings = cap / start;
    if ((doublings & (doublings - 1)) != 0) return 0;
    return cap == start || cap / 2 < n - 1;
}

/* The arrays a restore replaces (the rest of the engine stays). */
static void free_state(gr_edmd *t)
{
    free(t->P);
    free(t->mass);
    free(t->spin);
    free(t->image);
    free(t->sched);
    free(t->order.id_of);
    free(t->big.is_big);
    free(t->queue.item);
    free(t->queue.head);
    free(t->queue.near);
    free(t->cells.head);
    free(t->cells.next);
    free(t->cells.occ);
    free(t->nl.centre);
    free(t->nl.rows);
    free(t->nl.built);
    free(t->nl.lap);
    free(t->nl.expiry);
    free(t->nl.blocks);
}

/* t: a copy of s whose replaceable arrays are fresh, sized as s's (neighbour rows with
 * `cap` entries each).  GR_OK or GR_ERR_NOMEM (nothing left allocated). */
static int alloc_state(gr_edmd *t, const gr_edmd *s, int32_t cap)
{
    const size_t n = (size_t)s->n;
    const int d = s->dim;
    *t = *s;
    t->P = gr_big_alloc((n * GR_STRIDE(s->dim) * sizeof(double) + 63) / 64 * 64);
    t->mass = gr_big_alloc(n * sizeof(double));
    t->spin = s->spin ? malloc(n * GR_SPIN_DIM(d) * sizeof(double)) : NULL;
    t->image = calloc(n * d, sizeof(int64_t));
    t->sched = gr_big_alloc(n * sizeof(gr_sched));
    t->order.id_of = malloc(n * sizeof(int32_t));
    t->big.is_big = calloc(n, 1);
    t->queue.item = gr_big_alloc(n * sizeof(gr_cq_item));
    t->queue.head = gr_big_alloc((size_t)s->queue.nb * sizeof(int32_t));
    t->queue.near = malloc(n * sizeof(gr_cq_near));
    t->cells.head = gr_big_alloc((size_t)s->cells.ncells * sizeof(int32_t));
    t->cells.next = gr_big_alloc(n * sizeof(int32_t));
    t->cells.occ = calloc(cell_occ_words(s->cells.ncells), sizeof(uint64_t));
    const int lists = s->nl.shell > 0.0;
    t->nl.centre = lists ? gr_big_alloc(n * (d + 1) * sizeof(double)) : NULL;
    t->nl.rows = lists ? gr_big_alloc(n * (size_t)cap * sizeof(int32_t)) : NULL;
    t->nl.cap = cap;
    t->nl.built = s->nl.built ? malloc(n * sizeof(double)) : NULL;
    t->nl.lap = s->nl.built ? malloc(n) : NULL;
    t->nl.expiry = s->nl.built ? malloc(2 * n * sizeof(double)) : NULL;
    t->nl.blocks = s->nl.built ? gr_big_alloc((size_t)s->cells.ncells * GR_LE_BLOCK * sizeof(int32_t))
                               : NULL;
    if ((s->nl.built && (!t->nl.built || !t->nl.lap || !t->nl.expiry || !t->nl.blocks)) ||!t->P || !t->mass || (s->spin && !t->spin) || !t->image || !t->sched ||
        !t->order.id_of || !t->big.is_big || !t->queue.item || !t->queue.head || !t->queue.near || !t->cells.head ||
        !t->cells.next || !t->cells.occ ||
        (lists && (!t->nl.centre || !t->nl.rows))) {
        free_state(t);
        return GR_ERR_NOMEM;
    }
    return GR_OK;
}

/* The queue key schedule() gives a particle with this scheduling state. */
static double key_of(const gr_sched *e) { return e->t_coll < e->t_cross ? e->t_coll : e->t_cross; }

/* Whether t, read from a checkpoint, is a state that s (built from the same scene) could
 * have reached: NULL if so, else what is wrong.  seen: n bytes of zeroed scratch, left
 * dirty; skel: n int32 of scratch. */
static const char *check_state(const gr_edmd *t, const gr_edmd *s, uint8_t *seen, int32_t *skel)
{
    const int32_t n = s->n;
    const int d = s->dim;
    const gr_edmd_config *a = &t->cfg, *b = &s->cfg;
    if (a->dim != b->dim || a->n != b->n || a->periodic != b->periodic ||
        memcmp(a->lo, b->lo, sizeof a->lo) != 0 || memcmp(a->hi, b->hi, sizeof a->hi) != 0 ||
#define DIFFERS(field) !same_double(a->field, b->field) ||
        GR_SCENE_DOUBLES(DIFFERS)
#undef DIFFERS
        !same_double(a->cell_factor, b->cell_factor) || !same_double(a->big_ratio, b->big_ratio) ||
        !same_double(a->shell, b->shell) || a->stress != b->stress ||
        !same_double(a->gravity[0], b->gravity[0]) || !same_double(a->gravity[1], b->gravity[1]) ||
        !same_double(a->gravity[2], b->gravity[2]) || a->free_fall != b->free_fall)
        return "its box, restitution, contact duration, gravity or engine knobs differ from the "
               "scene's";
    if (a->vib.on != b->vib.on || a->vib.axis != b->vib.axis || a->vib.side != b->vib.side ||
        a->vib.waveform != b->vib.waveform || !same_double(a->vib.amplitude, b->vib.amplitude) ||
        !same_double(a->vib.omega, b->vib.omega) || !same_double(a->vib.phase, b->vib.phase))
        return "its vibrating wall differs from the scene's";
    if (!same_double(t->mass_total, s->mass_total))
        return "its total mass differs from the scene's";
    if (t->nl.broken != 0 && t->nl.broken != 1) return "its neighbour-list flag is corrupt";

    /* counters: each starts at 0 and grows by one at a time (order.next: events plus a
     * multiple of n), so a negative one is corrupt, and one past INT64_MAX / 2 (2^62
     * events: centuries at 1e9 a second) is one the next increments could overflow */
#define GR_COUNTER(x) {"its counter " #x " is negative or past INT64_MAX / 2", t->x}
    const struct {
        const char *why;
        int64_t value;
    } counters[] = {
        GR_COUNTER(events),      GR_COUNTER(pair),       GR_COUNTER(wall),
        GR_COUNTER(invalid),     GR_COUNTER(elastic_tc), GR_COUNTER(law_clamped),
        GR_COUNTER(crossings),   GR_COUNTER(shell_exits), GR_COUNTER(same_instant),
        GR_COUNTER(order.next),  GR_COUNTER(kicks),
    };
#undef GR_COUNTER
    for (size_t k = 0; k < sizeof counters / sizeof counters[0]; k++)
        if (counters[k].value < 0 || counters[k].value > INT64_MAX / 2) return counters[k].why;
    for (int32_t i = 0; i < n; i++)
        if (t->sched[i].count < 0 || t->sched[i].count > INT64_MAX / 2 || t->sched[i].pcount < 0 ||
            t->sched[i].pcount > INT64_MAX / 2)
            return "a particle's collision counter (count or pcount) is negative or past "
                   "INT64_MAX / 2";

    /* image counters: each change of one is a cell crossing or a shell exit through a
     * periodic box's face (edmd.c), so none exceeds their count in size, and between walls
     * all are 0.  Bounded so, a counter cannot overflow in a run before those two
     * counters pass INT64_MAX / 2 more (the bound above), and the unwrapped positions
     * (pos + image L) stay those the run made. */
    const int64_t moves = b->periodic ? t->crossings + t->shell_exits : 0; /* <= INT64_MAX */
    /* sheared: a y-face crossing also adds to img_x the box lengths in D(t) (boundary.h) */
    const double Dmax = s->le ? fabs(bd_le_total(b->shear_offset, s->le_u, t->t)) / s->L[0] + 2.0 : 0.0;
    for (size_t k = 0; k < (size_t)n * d; k++)
        if (s->le && k % (size_t)d == 0 ? !(fabs((double)t->image[k]) <= (double)moves * (Dmax + 1.0))
                                        : (t->image[k] < -moves || t->image[k] > moves))
            return "a particle's image counter is larger than the cell crossings and shell "
                   "exits that could have made it";

    /* the renumbering is a permutation; through it each particle has the radius, mass
     * and bigness the scene gives it (skel: the scene's index -> s's internal index) */
    for (int32_t i = 0; i < n; i++) {
        const int32_t u = t->order.id_of[i];
        if (u < 0 || u >= n || seen[u]) return "its particle numbering is not a permutation";
        seen[u] = 1;
    }
    for (int32_t k = 0; k < n; k++) skel[s->order.id_of[k]] = k;
    int32_t big = 0;
    for (int32_t i = 0; i < n; i++) {
        const int32_t k = skel[t->order.id_of[i]];
        if (!same_double(RAD(rec(t, d, i), d), RAD(rec(s, d, k), d)) ||
            !same_double(t->mass[i], s->mass[k]) || t->big.is_big[i] != s->big.is_big[k])
            return "a particle's radius, mass or bigness differs from the scene's";
        big += t->big.is_big[i];
    }
    if (big != t->big.n) return "its big particles are inconsistent";
    for (int32_t k = 0; k < t->big.n; k++) {
        const int32_t i = t->big.idx[k];
        if (i < 0 || i >= n || !t->big.is_big[i]) return "its big particles are inconsistent";
        for (int32_t m = 0; m < k; m++)
            if (t->big.idx[m] == i) return "its big particles are inconsistent";
    }

    /* numbers: the time and every particle clock finite (0 <= t_i <= t: a clock only
     * moves to an event's time), positions within a box length of the box (list mode
     * lets them stray a shell's width beyond a periodic box), list centres too, speeds
     * finite and within the scene's limit of 1e140 (granular/scene.py), counters of
     * energy finite.  Out-of-range numbers would make NaNs that the engine's cell
     * arithmetic is not built for. */
    if (!(t->t >= 0.0 && t->t < INFINITY) || !isfinite(t->eps_t) || !isfinite(t->kinetic) ||
        !isfinite(t->kinetic_time) || !isfinite(t->virial) || !isfinite(t->wall_impulse) ||
        !isfinite(t->shear_work) ||
        !isfinite(t->wall_work) || !isfinite(t->collision_loss) ||
        !isfinite(t->momentum[0]) || !isfinite(t->momentum[1]) || !isfinite(t->momentum[2]) ||
        t->t_prev_event != t->t_prev_event)
        return "its time or energy counters are not finite";
    if (!(t->stress_t >= 0.0 && t->stress_t <= t->t)) return "its stress tensor's clock is out of range";
    for (int k = 0; k < 9; k++)
        if (!isfinite(t->st_coll[k]) || !isfinite(t->st_kin[k]) || !isfinite(t->st_kin_time[k]))
            return "its stress tensor is not finite";
    /* the next kick lies ahead (none without driving), and the energy kicks gave is finite */
    if (!isfinite(t->drive_energy) ||
        (b->drive_kind != GR_DRIVE_NONE ? !(t->drive_next >= t->t && t->drive_next < INFINITY)
                                        : t->drive_next != INFINITY || t->kicks != 0))
        return "its random driving's state (next kick, kicks, energy given) is corrupt";
    for (int32_t i = 0; i < n; i++) {
        const double *p = rec(t, d, i);
        if (!(TIME(p, d) >= 0.0 && TIME(p, d) <= t->t)) return "a particle's clock is out of range";
        for (int k = 0; k < d; k++) {
            const double L = s->L[k];
            if (!(p[k] >= b->lo[k] - L && p[k] <= b->hi[k] + L) || !(fabs(VEL(p, d)[k]) <= 1e140))
                return "a particle's position or velocity is out of range";
            if (s->nl.shell > 0.0) {
                const double x = t->nl.centre[(size_t)i * (d + 1) + k];
                if (!(x >= b->lo[k] - L && x <= b->hi[k] + L))
                    return "a neighbour list's centre is out of range";
            }
        }
        if (s->nl.shell > 0.0 && !same_double(t->nl.centre[(size_t)i * (d + 1) + d], RAD(p, d)))
            return "a neighbour list's centre is corrupt";
        if (t->nl.built && !(t->nl.built[i] >= 0.0 && t->nl.built[i] <= t->t))
            return "a neighbour list's build time is out of range";
        if (t->spin)
            for (int k = 0; k < GR_SPIN_DIM(d); k++)
                if (!(fabs(t->spin[(size_t)i * GR_SPIN_DIM(d) + k]) <= 1e140))
                    return "a particle's angular velocity is out of range";
    }

    /* scheduling states: every index an event follows is in range; a particle with no
     * partner has no collision and one with no crossing has no crossing time, so the
     * loop never takes them for a wall or a crossing of axis -1 */
    const int lists = s->nl.shell > 0.0;
    const int32_t codes = d == 3 ? 27 : 9;
    for (int32_t i = 0; i < n; i++) {
        const gr_sched *e = &t->sched[i];
        /* (a sheared box's slide event: partner -2 - 2 d, lees_edwards.h) */
        if (e->partner < -1 - 2 * d - s->le || e->partner >= n || e->last < -1 - 2 * d ||
            e->last >= n)
            return "a particle's partner index is out of range";
        /* predictions are made from the particle's clock on (NaN is reported by the loop) */
        const double clock = TIME(rec(t, d, i), d);
        if (e->t_coll < clock || e->t_cross < clock) return "a particle's next event lies in its past";
        if (e->partner == -1 && e->t_coll != INFINITY)
            return "a particle has a collision time but no partner";
        /* (lists: t_cross is the shell exit, and cross is not used) */
        if (e->cross < -1 || e->cross >= 2 * d || (!lists && e->cross == -1 && e->t_cross < INFINITY))
            return "a particle's cell crossing is out of range";
        for (int k = 0; k < d; k++)
            if (e->c[k] < 0 || e->c[k] >= s->cells.nc[k]) return "a particle's cell is out of range";
        if (e->nn < 0 || e->nn > (lists ? t->nl.cap : 0))
            return "a neighbour list's length is out of range";
        if (lists)
            for (int k = 0; k < e->nn; k++) {
                const int32_t entry = nl_row(&t->nl, i)[k];
                if (entry < 0 || (entry >> GR_NL_BITS) >= n || (entry & GR_NL_CODE_MASK) >= codes)
                    return "a neighbour list entry is out of range";
            }
        const double key = key_of(e), queued = t->queue.item[i].t;
        if (!same_double(key, queued) && !(key != key && queued != queued))
            return "a particle's queue key is not its next event";
    }

    /* the queue (its own invariants), then the cell lists: each particle that is not
     * big in exactly the list of its cell */
    memset(seen, 0, (size_t)n);
    const char *fault = gr_cq_check(&t->queue, seen);
    if (fault) return fault;
    memset(seen, 0, (size_t)n);
    const gr_cells *g = &t->cells;
    int32_t filed = 0;
    for (int32_t cell = 0; cell < g->ncells; cell++) {
        for (int32_t i = g->head[cell]; i != -1; i = g->next[i]) {
            if (i < 0 || i >= n || seen[i] || t->big.is_big[i] ||
                cell_of(g, d, t->sched[i].c) != cell)
                return "the cell lists are corrupt";
            seen[i] = 1;
            filed++;
        }
    }
    if (filed != n - t->big.n) return "the cell lists do not hold every particle";
    return NULL;
}

/* Whether row i lists entry e. */
static int listed(const gr_edmd *t, int32_t i, int32_t e)
{
    const int32_t *row = nl_row(&t->nl, i);
    for (int k = 0; k < t->sched[i].nn; k++)
        if (row[k] == e) return 1;
    return 0;
}

/* check_lists in a sheared box (nlist.h, le_cells.h): every centre filed in the box, in
 * the cell of its filed x, with at most a lap; and every pair listed whose centres, carried
 * by the flow from the later of their builds for a list's life, come within reach (up to
 * rounding, as check_lists), through the image found then. */
static const char *check_sheared_lists(const gr_edmd *t)
{
    const int d = t->dim;
    const gr_cells *g = &t->cells;
    if (!(isfinite(t->nl.tref) && t->nl.tref <= t->t + t->nl.span))
        return "a neighbour list's filing time is out of range";
    for (int32_t i = 0; i < t->n; i++) {
        const double *ci = t->nl.centre + (size_t)i * (d + 1);
        int32_t c[3] = {0, 0, 0};
        cell_coords(g, d, ci, c);
        if (!(ci[0] >= g->lo[0] && ci[0] < g->lo[0] + t->nl.lx) || t->nl.lap[i] < -1 ||
            t->nl.lap[i] > 1 || cell_of(g, d, c) != cell_of(g, d, t->sched[i].c))
            return "a neighbour list's centre is filed in another cell than the flow's";
    }
    for (int32_t i = 0; i < t->n; i++) {
        const double tbi = t->nl.built[i];
        const double *ci = t->nl.centre + (size_t)i * (d + 1);
        const double point[4] = {le_centre_x(&t->nl, ci, t->nl.lap[i], tbi), ci[1],
                                 d == 3 ? ci[2] : ci[d], ci[d]};
        const int32_t m = le_gather(t, d, point, tbi, i, 0, 1.0 - 1e-9, t->nl.near,
                                    le_test_scalar);
        for (int32_t k = 0; k < m; k++) {
            const int32_t j = t->nl.near[k] >> GR_NL_BITS;
            if (t->nl.built[j] <= tbi && !listed(t, i, t->nl.near[k]))
                return "a neighbour list misses a particle within reach";
        }
    }
    return NULL;
}

/* List mode, on a state whose numbers, cells and occupancy bits are right: whether its
 * neighbour lists are what the engine keeps (nlist.h) -- every entry listed back the
 * other way through the opposite image, and every pair whose centres lie within
 * r_i + r_j + 2 delta of each other listed (up to rounding: a pair within a billionth
 * of that distance of the edge may be missing; it cannot touch before one of the two
 * leaves its shell).  A list that missed a pair would let it pass through each other.
 * NULL if so, else what is wrong. */
static const char *check_lists(const gr_edmd *t)
{
    const int d = t->dim;
    for (int32_t i = 0; i < t->n; i++) {
        const int32_t *row = nl_row(&t->nl, i);
        for (int k = 0; k < t->sched[i].nn; k++) {
            const int32_t j = row[k] >> GR_NL_BITS, code = row[k] & GR_NL_CODE_MASK;
            if (j == i || !listed(t, j, (i << GR_NL_BITS) | (2 * GR_NL_CODE_NONE(d) - code)))
                return "a neighbour list is not listed back the other way";
        }
    }
    if (t->le) return check_sheared_lists(t);
    for (int32_t i = 0; i < t->n; i++) {
        const double *ci = t->nl.centre + (size_t)i * (d + 1);
        gr_nbr nb[27];
        const int count = cell_neighbours(&t->cells, d, t->sched[i].c, -1, 0, nb);
        for (int k = 0; k < count; k++) {
            const int32_t code = nl_code(d, nb[k].shift);
            for (int32_t j = t->cells.head[nb[k].cell]; j >= 0; j = t->cells.next[j]) {
                const double *cj = t->nl.centre + (size_t)j * (d + 1);
                double d2 = 0.0;
                for (int a = 0; a < d; a++) {
                    const double x = cj[a] + nb[k].shift[a] - ci[a];
                    d2 += x * x;
                }
                const double cut = (ci[d] + cj[d] + 2.0 * t->nl.shell) * (1.0 - 1e-9);
                if (j != i && d2 < cut * cut && !listed(t, i, (j << GR_NL_BITS) | code))
                    return "a neighbour list misses a particle within reach";
            }
        }
    }
    return NULL;
}

int gr_edmd_restore(gr_edmd *s, const unsigned char *buf, size_t size, gr_error *err)
{
    cursor c = {NULL, buf, size, 0, 0, 0};
    header h, want = header_of(s, size);
    io_header(&c, &h);
    const char *what = NULL;
    if (c.bad || memcmp(h.magic, magic, sizeof magic) != 0) what = "not an engine checkpoint";
    else if (h.byte_order != GR_BYTE_ORDER_MARK) what = "written on a machine of the other byte order";
    else if (h.version != GR_CHECKPOINT_VERSION || h.layout != want.layout)
        what = "written by a build with another state layout";
    else if (h.total != size) what = "truncated, or with bytes appended";
    else if (h.n != want.n || h.dim != want.dim || h.stride != want.stride || h.lists != want.lists ||
             h.nb != want.nb || h.ncells != want.ncells || memcmp(h.nc, want.nc, sizeof h.nc) != 0 ||
             h.big_n != want.big_n || h.spin != want.spin)
        what = "made for another scene or other engine knobs (sizes differ)";
    else if (h.lists && !(h.cap >= want.cap && cap_reachable(h.cap, h.dim, h.n)))
        what = "its neighbour-list capacity (header field cap) is out of range: not a "
               "doubling of the start, or more than twice the particles the lists can hold";
    else if (!h.lists && h.cap != want.cap)
        what = "its neighbour-list capacity (header field cap) is out of range";
    if (what) {
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, NAN, what);
        return GR_ERR_VALUE;
    }

    gr_edmd t;
    int status = alloc_state(&t, s, h.cap);
    if (status != GR_OK) return status;
    uint8_t *seen = calloc((size_t)s->n, 1);
    int32_t *skel = malloc((size_t)s->n * sizeof *skel);
    if (!seen || !skel) {
        status = GR_ERR_NOMEM;
    } else {
        transfer(&c, &t);
        if (c.law_differs)
            what = "its restitution law (pair or wall: kind, parameters or table) differs from "
                   "the scene's";
        else if (c.bad || c.at != size) what = "truncated or corrupt";
        else what = check_state(&t, s, seen, skel);
        if (what) status = GR_ERR_VALUE;
    }
    free(seen);
    free(skel);
    if (status != GR_OK) {
        free_state(&t);
        if (status == GR_ERR_VALUE) gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, NAN, what);
        return status;
    }
    /* the occupancy bits follow from the lists (checked); in a sheared box so do the
     * cells' blocks, the offset at the filing time and each list's expiry */
    for (int32_t cell = 0; cell < t.cells.ncells; cell++)
        if (t.cells.head[cell] >= 0) t.cells.occ[cell >> 6] |= (uint64_t)1 << (cell & 63);
    if (t.nl.built) {
        memset(t.nl.blocks, 0, (size_t)t.cells.ncells * GR_LE_BLOCK * sizeof(int32_t));
        le_sync_all(&t.cells, t.nl.blocks);
        t.nl.dref = bd_le_offset(t.cfg.shear_offset, t.le_u, t.nl.tref, t.nl.lx);
        for (int32_t i = 0; i < t.n; i++)
            le_expiry(&t, t.nl.centre + (size_t)i * (t.dim + 1), t.nl.built[i],
                      t.nl.expiry + 2 * (size_t)i);
    }
    if (t.nl.shell > 0.0 && (what = check_lists(&t)) != NULL) {
        free_state(&t);
        gr_error_set(err, GR_ERR_VALUE, -1, -1, NAN, NAN, what);
        return GR_ERR_VALUE;
    }
    free_state(s);
    *s = t;
    return GR_OK;
}
