/* edmd_dim.h -- the event-driven loop, specialised for one dimension.
 *
 * Included twice by edmd.c, with DIM = 2 and DIM = 3 and FN(name) appending _2d / _3d,
 * so that a 2D scene never pays for a third dimension and every loop over axes has a
 * constant trip count.  Reading order: neighbours -> predict -> events -> advance.
 *
 * A particle record is P[i*stride ...] = x[DIM] v[DIM] t r: position at the particle's own
 * time t, velocity, radius.  Times are absolute. */

#define X(p) (p)
#define V(p) ((p) + DIM)
#define T(p) ((p)[2 * DIM])
#define R(p) ((p)[2 * DIM + 1])

typedef struct {
    int32_t cell;
    double shift[DIM];
} FN(nbr);

/* The occupied cells adjacent to cell coordinates c (itself included), with the image
 * shift to add to positions found there.  With axis >= 0 only the layer at offset dir
 * along that axis (the cells that become adjacent when crossing in that direction).
 * Returns the count.  The general way, for cells at the box edge: every candidate cell
 * is looked at in a loop of fixed length and kept or not without a branch, because
 * which of them are occupied, or beyond a wall, is as good as random. */
static inline int FN(neighbours)(const gr_edmd *s, const int32_t *c, int axis, int dir,
                                 FN(nbr) *out)
{
    /* the offsets along each axis: -1, 0, 1, or along `axis` only dir (three times) */
    int d[3][3];
    for (int a = 0; a < 3; a++)
        for (int k = 0; k < 3; k++) d[a][k] = a == axis ? dir : k - 1;
    const int n2 = DIM == 3 && axis != 2 ? 3 : 1, n1 = axis != 1 ? 3 : 1, n0 = axis != 0 ? 3 : 1;
    int m = 0;
    for (int k2 = 0; k2 < n2; k2++) {
#if DIM == 3
        const int32_t q2 = s->nb_cell[2][3 * c[2] + d[2][k2] + 1];
        const double sh2 = s->nb_shift[2][3 * c[2] + d[2][k2] + 1];
#else
        const int32_t q2 = 0;
#endif
        for (int k1 = 0; k1 < n1; k1++) {
            const int32_t q1 = s->nb_cell[1][3 * c[1] + d[1][k1] + 1];
            const double sh1 = s->nb_shift[1][3 * c[1] + d[1][k1] + 1];
            for (int k0 = 0; k0 < n0; k0++) {
                const int32_t q0 = s->nb_cell[0][3 * c[0] + d[0][k0] + 1];
                const int inside = (q0 >= 0) & (q1 >= 0) & (q2 >= 0); /* not beyond a wall */
                const int32_t cell = inside ? (q2 * s->nc[1] + q1) * s->nc[0] + q0 : 0;
                out[m].cell = cell;
                out[m].shift[0] = s->nb_shift[0][3 * c[0] + d[0][k0] + 1];
                out[m].shift[1] = sh1;
#if DIM == 3
                out[m].shift[2] = sh2;
#endif
                m += inside & cell_occupied(s, cell);
            }
        }
    }
    return m;
}

static inline int32_t FN(cell_of)(const gr_edmd *s, const int32_t *c)
{
#if DIM == 3
    return (c[2] * s->nc[1] + c[1]) * s->nc[0] + c[0];
#else
    return c[1] * s->nc[0] + c[0];
#endif
}

/* Set i's cell coordinates from its position (clamped: rounding may leave a particle a
 * hair outside the box). */
static inline void FN(file_in_cell)(gr_edmd *s, int32_t i)
{
    const double *p = rec(s, i);
    for (int a = 0; a < DIM; a++) {
        double f = floor((X(p)[a] - s->cfg.lo[a]) / s->w[a]);
        s->ev[i].c[a] = f < 0.0 ? 0 : f >= s->nc[a] ? s->nc[a] - 1 : (int32_t)f;
    }
}

/* Everything an event of particle i is about to read or write, requested at once.  A
 * macro, not a function: GCC takes a function that only prefetches for one without
 * effects and deletes the calls (seen with GCC 12 at -O3: none of these was emitted). */
#define PREFETCH_PARTICLE(s, i)                                                          \
    do {                                                                                \
        GR_PREFETCH(rec((s), (i)));                                                      \
        GR_PREFETCH(&(s)->ev[(i)]);                                                      \
        GR_PREFETCH(&(s)->next[(i)]);                                                    \
        GR_PREFETCH(&(s)->prev[(i)]);                                                    \
        GR_CQ_PREFETCH(&(s)->queue, (i));                                                \
        if ((s)->nl) GR_PREFETCH((s)->nl + (size_t)(i) * (s)->nl_cap);                  \
    } while (0)

static inline void FN(move)(double *p, double t)
{
    double dt = t - T(p);
    for (int a = 0; a < DIM; a++) X(p)[a] += V(p)[a] * dt;
    T(p) = t;
}

/* A pair that collided with each other at this very instant cannot approach again in
 * exact arithmetic (the normal relative velocity became -xi times the old one); any
 * approach left is rounding, e.g. after xi = 0. */
static inline int FN(rebound_now)(const gr_edmd *s, int32_t i, int32_t j, double t, double dt)
{
    return dt == 0.0 && s->ev[i].last == j && s->ev[j].last == i && s->ev[i].t_last == t &&
           s->ev[j].t_last == t;
}

/* One candidate j (not i) for i's next pair collision (record p, clock at t): j seen
 * through an image shift (NULL: none) or, with `nearest`, through the nearest periodic
 * image.  Keeps the earliest in *best / *partner; `best` is relative to t and is also the
 * horizon for the early exit in gr_pair_beats.  Every scan calls this with constant
 * shift and nearest arguments, so each gets its own inlined copy. */
static inline void FN(try_pair)(const gr_edmd *s, int32_t i, const double *p, int32_t j,
                                const double *shift, int nearest, double *best,
                                int32_t *partner)
{
    const double *q = rec(s, j);
    double dtj = T(p) - T(q), dr[DIM], dv[DIM];
    for (int a = 0; a < DIM; a++) {
        dr[a] = X(q)[a] + V(q)[a] * dtj - X(p)[a];
        if (shift) dr[a] += shift[a];
        if (nearest) dr[a] = nearest_image(dr[a], s->L[a]);
        dv[a] = V(q)[a] - V(p)[a];
    }
    double dt;
    if (!gr_pair_beats(DIM, dr, dv, R(p) + R(q), *best, &dt)) return;
    if (FN(rebound_now)(s, i, j, T(p), dt)) return;
    *best = dt;
    *partner = j;
    GR_PREFETCH(&s->ev[j]); /* its collision count is read when the scan ends */
}

/* The earliest pair collision of i found by a scan, if it beats i's prediction. */
static inline void FN(keep_pair)(gr_edmd *s, int32_t i, double best, int32_t partner)
{
    if (partner < 0) return;
    gr_event *e = &s->ev[i];
    e->t_coll = T(rec(s, i)) + best;
    e->partner = partner;
    e->pcount = s->ev[partner].count;
}

/* Pair collisions of i with the particles of one cell, seen through an image shift. */
static inline void FN(scan_cell)(const gr_edmd *s, int32_t i, const double *p, int32_t cell,
                                 const double *shift, double *best, int32_t *partner)
{
    for (int32_t j = s->head[cell]; j >= 0; j = s->next[j])
        if (j != i) FN(try_pair)(s, i, p, j, shift, 0, best, partner);
}

/* The pair (i, j), j seen through the nearest periodic image (the one that touches:
 * contact distances are below half the box), for scans that involve a big particle. */
static inline void FN(scan_one)(const gr_edmd *s, int32_t i, const double *p, int32_t j,
                                double *best, int32_t *partner)
{
    if (j != i) FN(try_pair)(s, i, p, j, NULL, s->cfg.periodic, best, partner);
}

/* The cells within reach of big particle i (clock at t): the block of R cells each way
 * (axis < 0), or the layer of it newly reached after crossing along `axis` in direction
 * `dir`.  choose_big() keeps the block narrower than the box, so a periodic block never
 * meets itself. */
static void FN(scan_block)(const gr_edmd *s, int32_t i, int axis, int dir, double *best,
                           int32_t *partner)
{
    const double *p = rec(s, i);
    const int32_t *c = s->ev[i].c;
    int32_t lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < DIM; a++) {
        int32_t reach = (int32_t)ceil((R(p) + s->r_small) / s->w[a]);
        lo[a] = a == axis ? c[a] + dir * reach : c[a] - reach;
        hi[a] = a == axis ? lo[a] : c[a] + reach;
        if (!s->cfg.periodic) {
            if (lo[a] < 0) lo[a] = 0;
            if (hi[a] > s->nc[a] - 1) hi[a] = s->nc[a] - 1;
            if (lo[a] > hi[a]) return; /* the layer lies beyond a wall */
        }
    }
    int32_t q[3] = {0, 0, 0};
    for (int32_t k2 = lo[DIM - 1]; k2 <= hi[DIM - 1]; k2++) {
        q[DIM - 1] = (k2 % s->nc[DIM - 1] + s->nc[DIM - 1]) % s->nc[DIM - 1];
#if DIM == 3
        for (int32_t k1 = lo[1]; k1 <= hi[1]; k1++) {
            q[1] = (k1 % s->nc[1] + s->nc[1]) % s->nc[1];
#else
        {
#endif
            for (int32_t k0 = lo[0]; k0 <= hi[0]; k0++) {
                q[0] = (k0 % s->nc[0] + s->nc[0]) % s->nc[0];
                int32_t cell = FN(cell_of)(s, q);
                if (!cell_occupied(s, cell)) continue;
                for (int32_t j = s->head[cell]; j >= 0; j = s->next[j])
                    FN(scan_one)(s, i, p, j, best, partner);
            }
        }
    }
}

/* Look for pair collisions of i (whose clock is at t) in all adjacent cells (axis < 0) or
 * in the layer newly adjacent after crossing along `axis` in direction `dir`; keep the
 * earliest in i's event if it beats the one there. */
static void FN(scan)(gr_edmd *s, int32_t i, int axis, int dir)
{
    const double *p = rec(s, i);
    const int32_t *c = s->ev[i].c;
    gr_event *e = &s->ev[i];
    double best = e->t_coll - T(p);
    int32_t partner = -1;
    int interior = 1;
    for (int a = 0; a < DIM; a++) /* 1 <= c[a] <= nc[a] - 2, in one unsigned comparison */
        interior &= (uint32_t)(c[a] - 1) < (uint32_t)(s->nc[a] - 2);
    if (s->n_big && s->is_big[i]) {
        FN(scan_block)(s, i, axis, dir, &best, &partner);
    } else if (interior) {
        const int32_t base = FN(cell_of)(s, c);
        const int32_t *off = axis < 0 ? s->off_all : s->off_layer[2 * axis + (dir > 0)];
        const int count = axis < 0 ? (DIM == 3 ? 27 : 9) : (DIM == 3 ? 9 : 3);
        /* in a grid too large for the cache, the occupied cells' heads first, all at
         * once: they are misses, and the chained loads of the scan would otherwise wait
         * for them one by one (in a small grid the loop costs more than it saves: its
         * length, the number of occupied cells, is a branch mispredicted often) */
        int32_t full[27];
        int m = 0;
        for (int k = 0; k < count; k++) {
            int32_t cell = base + off[k];
            full[m] = cell;
            m += cell_occupied(s, cell);
        }
        if (s->prefetch_heads)
            for (int k = 0; k < m; k++) GR_PREFETCH(&s->head[full[k]]);
        for (int k = 0; k < m; k++) FN(scan_cell)(s, i, p, full[k], NULL, &best, &partner);
    } else {
        FN(nbr) nb[DIM == 3 ? 27 : 9];
        int count = FN(neighbours)(s, c, axis, dir, nb);
        for (int k = 0; k < count; k++)
            FN(scan_cell)(s, i, p, nb[k].cell, nb[k].shift, &best, &partner);
    }
    for (int32_t b = 0; b < s->n_big; b++) FN(scan_one)(s, i, p, s->big[b], &best, &partner);
    FN(keep_pair)(s, i, best, partner);
}

/* List mode: pair collisions of i (clock at t) with its listed neighbours, before its
 * predicted wall collision and its shell exit (which rebuilds and predicts afresh, so
 * later collisions need not be found now: most candidates then fail the cheap test). */
static void FN(scan_list)(gr_edmd *s, int32_t i)
{
    const double *p = rec(s, i);
    gr_event *e = &s->ev[i];
    const int32_t *row = s->nl + (size_t)i * s->nl_cap;
    double best = (e->t_coll < e->t_cross ? e->t_coll : e->t_cross) - T(p);
    int32_t partner = -1;
    for (int k = 0; k < e->nn; k++)
        FN(try_pair)(s, i, p, row[k] >> GR_NL_BITS, s->img[row[k] & ((1 << GR_NL_BITS) - 1)],
                     0, &best, &partner);
    FN(keep_pair)(s, i, best, partner);
}

/* List mode: when i leaves the sphere of radius delta about its list centre. */
static inline void FN(predict_exit)(gr_edmd *s, int32_t i)
{
    const double *p = rec(s, i);
    const double *centre = s->centre + (size_t)i * (DIM + 1);
    double a = 0.0, b = 0.0, c = -s->exit2;
    for (int k = 0; k < DIM; k++) {
        const double d = X(p)[k] - centre[k], v = V(p)[k];
        a += v * v;
        b += d * v;
        c += d * d;
    }
    /* the larger root of a dt^2 + 2 b dt + c = 0 with c < 0, in the form without
     * cancellation; c >= 0 is a hair outside by rounding: leave now */
    double dt;
    if (!(a > 0.0)) dt = INFINITY;
    else if (c >= 0.0) dt = 0.0;
    else {
        const double q = sqrt(b * b - a * c);
        dt = b > 0.0 ? -c / (b + q) : (q - b) / a;
    }
    s->ev[i].t_cross = T(p) + dt;
}

/* List mode: list i and every particle whose centre is within r_i + r_j + 2 delta of
 * i's (only those numbered above i if `above`: building all lists at once). */
static int FN(link_near)(gr_edmd *s, int32_t i, int above, gr_error *err)
{
    const double *ci = s->centre + (size_t)i * (DIM + 1);
    const double reach = ci[DIM] + 2.0 * s->shell;
    FN(nbr) nb[DIM == 3 ? 27 : 9];
    const int count = FN(neighbours)(s, s->ev[i].c, -1, 0, nb);
    /* first the new neighbours, kept or not without a branch (about one candidate in
     * six is kept: as good as random) */
    int32_t m = 0, *near = s->nl_near;
    for (int k = 0; k < count; k++) {
        int32_t code = 0;
        for (int a = DIM - 1; a >= 0; a--)
            code = 3 * code + (nb[k].shift[a] > 0.0) - (nb[k].shift[a] < 0.0) + 1;
        for (int32_t j = s->head[nb[k].cell]; j >= 0; j = s->next[j]) {
            const double *cj = s->centre + (size_t)j * (DIM + 1);
            double d2 = 0.0;
            for (int a = 0; a < DIM; a++) {
                const double d = cj[a] + nb[k].shift[a] - ci[a];
                d2 += d * d;
            }
            const double cut = cj[DIM] + reach;
            near[m] = (j << GR_NL_BITS) | code;
            m += (d2 < cut * cut) & (j != i) & (!above | (j > i));
        }
    }
    for (int32_t k = 0; k < m; k++) {
        int status = nl_link(s, i, near[k] >> GR_NL_BITS, near[k] & ((1 << GR_NL_BITS) - 1), err);
        if (status != GR_OK) return status;
    }
    return GR_OK;
}

/* List mode: make i's position (in the box) its list centre and file it in that cell. */
static inline void FN(set_centre)(gr_edmd *s, int32_t i)
{
    const double *p = rec(s, i);
    double *centre = s->centre + (size_t)i * (DIM + 1);
    centre[DIM] = R(p);
    for (int a = 0; a < DIM; a++) centre[a] = X(p)[a];
    FN(file_in_cell)(s, i);
}

/* Next cell crossing of i from its current position, cell and velocity. */
static inline void FN(predict_cross)(gr_edmd *s, int32_t i)
{
    /* Without branches on the signs of the velocity: they differ from one event to the
     * next at random, and a mispredicted branch costs more than the arithmetic. */
    const double *p = rec(s, i);
    const int32_t *c = s->ev[i].c;
    double best = INFINITY;
    int32_t code = -1;
    for (int a = 0; a < DIM; a++) {
        const double v = V(p)[a];
        const int up = v > 0.0;
        /* a wall has no cell behind it */
        const int open = s->cfg.periodic | (up & (c[a] < s->nc[a] - 1)) | (!up & (c[a] > 0));
        const double bound = s->cfg.lo[a] + (c[a] + up) * s->w[a];
        double dt = (bound - X(p)[a]) / (v != 0.0 ? v : 1.0);
        dt = dt < 0.0 ? 0.0 : dt; /* rounding left it a hair past the boundary */
        dt = (v != 0.0) & open ? dt : INFINITY;
        const int32_t earlier = dt < best;
        code += earlier * (2 * a + up - code); /* arithmetic: a select compiles to a branch */
        best = earlier ? dt : best;
    }
    s->ev[i].t_cross = T(p) + best;
    s->ev[i].cross = (int8_t)code;
}

static inline void FN(schedule)(gr_edmd *s, int32_t i)
{
    const gr_event *e = &s->ev[i];
    gr_cq_update(&s->queue, i, e->t_coll < e->t_cross ? e->t_coll : e->t_cross);
}

/* Full prediction for i, whose clock must be the current time: walls, all adjacent
 * cells, the next crossing. */
static void FN(predict)(gr_edmd *s, int32_t i)
{
    const double *p = rec(s, i);
    gr_event *e = &s->ev[i];
    e->t_coll = INFINITY;
    e->partner = -1;
    if (!s->cfg.periodic) {
        double best = INFINITY;
        int32_t wall = -1;
        for (int a = 0; a < DIM; a++) {
            double v = V(p)[a], dt;
            if (v > 0.0) dt = (s->cfg.hi[a] - R(p) - X(p)[a]) / v;
            else if (v < 0.0) dt = (s->cfg.lo[a] + R(p) - X(p)[a]) / v;
            else continue;
            if (dt < 0.0) dt = 0.0;
            if (dt < best) {
                best = dt;
                wall = 2 * a + (v > 0.0);
            }
        }
        if (wall >= 0) {
            e->t_coll = T(p) + best;
            e->partner = -2 - wall;
        }
    }
    if (s->nl) {
        FN(predict_exit)(s, i);
        FN(scan_list)(s, i);
    } else {
        FN(scan)(s, i, -1, 0);
        FN(predict_cross)(s, i);
    }
    FN(schedule)(s, i);
}

/* Collapse bookkeeping for a collision of i at t: count collisions that follow the
 * previous one of the same particle within eps_t. */
static inline int FN(streak)(gr_edmd *s, int32_t i, double t)
{
    gr_event *e = &s->ev[i];
    if (t - e->t_last <= s->eps_t) e->streak += e->streak < INT8_MAX;
    else e->streak = 0;
    e->t_last = t;
    return e->streak > GR_COLLAPSE_STREAK;
}

static int FN(do_cross)(gr_edmd *s, int32_t i, double t)
{
    double *p = rec(s, i);
    gr_event *e = &s->ev[i];
    int32_t *c = s->ev[i].c;
    const int a = e->cross >> 1, dir = (e->cross & 1) ? 1 : -1;
    FN(move)(p, t);
    int32_t old = FN(cell_of)(s, c);
    int32_t q = c[a] + dir;
    if (q >= s->nc[a]) {
        q = 0;
        X(p)[a] -= s->L[a];
        s->image[(size_t)i * DIM + a]++;
    } else if (q < 0) {
        q = s->nc[a] - 1;
        X(p)[a] += s->L[a];
        s->image[(size_t)i * DIM + a]--;
    }
    c[a] = q;
    if (!s->is_big[i]) {
        cell_remove(s, i, old);
        cell_insert(s, i, FN(cell_of)(s, c));
    }
    s->crossings++;
    FN(predict_cross)(s, i);
    FN(scan)(s, i, a, dir);
    FN(schedule)(s, i);
    return GR_OK;
}

/* List mode: i (clock at t) has left its shell.  Its list is rebuilt about its present
 * position, which is first brought back into a periodic box (between rebuilds a
 * particle may stray up to delta beyond the box: pair tests take the nearest image). */
static int FN(do_rebuild)(gr_edmd *s, int32_t i, double t, gr_error *err)
{
    double *p = rec(s, i);
    gr_event *e = &s->ev[i];
    FN(move)(p, t);
    const int32_t *row = s->nl + (size_t)i * s->nl_cap;
    /* the neighbours' list lengths and rows are misses: ask for all of them first */
    for (int k = 0; k < e->nn; k++) {
        GR_PREFETCH(&s->ev[row[k] >> GR_NL_BITS]);
        GR_PREFETCH(s->nl + (size_t)(row[k] >> GR_NL_BITS) * s->nl_cap);
    }
    for (int k = 0; k < e->nn; k++) nl_unlink(s, row[k] >> GR_NL_BITS, i);
    e->nn = 0;
    if (s->cfg.periodic) {
        for (int a = 0; a < DIM; a++) {
            if (X(p)[a] >= s->cfg.hi[a]) {
                X(p)[a] -= s->L[a];
                s->image[(size_t)i * DIM + a]++;
            } else if (X(p)[a] < s->cfg.lo[a]) {
                X(p)[a] += s->L[a];
                s->image[(size_t)i * DIM + a]--;
            }
        }
    }
    const int32_t old = FN(cell_of)(s, e->c);
    FN(set_centre)(s, i);
    const int32_t cell = FN(cell_of)(s, e->c);
    if (cell != old) {
        cell_remove(s, i, old);
        cell_insert(s, i, cell);
    }
    int status = FN(link_near)(s, i, 0, err);
    if (status != GR_OK) return status;
    s->crossings++;
    FN(predict)(s, i);
    return GR_OK;
}

static inline double FN(kinetic_of)(const gr_edmd *s, int32_t i)
{
    const double *v = V(rec(s, i));
    double v2 = 0.0;
    for (int a = 0; a < DIM; a++) v2 += v[a] * v[a];
    return 0.5 * s->mass[i] * v2;
}

static int FN(do_pair)(gr_edmd *s, int32_t i, int32_t j, double t, gr_error *err)
{
    double *p = rec(s, i), *q = rec(s, j);
    FN(move)(p, t);
    FN(move)(q, t);
    double dr[DIM];
    for (int a = 0; a < DIM; a++) {
        dr[a] = X(q)[a] - X(p)[a];
        /* contact distance < L/2, so the nearest image is the one */
        if (s->cfg.periodic) dr[a] = nearest_image(dr[a], s->L[a]);
    }
    double xi = s->cfg.restitution;
    if (s->cfg.contact_duration > 0.0 && xi < 1.0 &&
        (t - s->ev[i].t_last < s->cfg.contact_duration ||
         t - s->ev[j].t_last < s->cfg.contact_duration)) {
        xi = 1.0; /* TC model: within t_c of a previous collision, collide elastically */
        s->elastic_tc++;
    }
    double before = FN(kinetic_of)(s, i) + FN(kinetic_of)(s, j);
    double vir = gr_pair_collide(DIM, dr, V(p), V(q), s->mass[i], s->mass[j], xi);
    if (vir < 0.0) { /* grazing: no longer approaching at contact after rounding */
        s->invalid++;
        FN(predict)(s, i);
        FN(predict)(s, j);
        return GR_OK;
    }
    s->kinetic += FN(kinetic_of)(s, i) + FN(kinetic_of)(s, j) - before;
    s->virial += vir;
    s->pair++;
    s->ev[i].count++;
    s->ev[j].count++;
    int collapse_i = FN(streak)(s, i, t), collapse_j = FN(streak)(s, j, t);
    s->ev[i].last = j;
    s->ev[j].last = i;
    if (collapse_i || collapse_j) {
        gr_error_set(err, GR_ERR_COLLAPSE, uid(s, i), uid(s, j), t, (double)GR_COLLAPSE_STREAK,
                     GR_XSTR(GR_COLLAPSE_STREAK) " successive collisions of one particle, "
                     "each within 1e-9 of a free-flight time of the previous");
        FN(predict)(s, i);
        FN(predict)(s, j);
        return GR_ERR_COLLAPSE;
    }
    FN(predict)(s, i);
    FN(predict)(s, j);
    return GR_OK;
}

static int FN(do_wall)(gr_edmd *s, int32_t i, int wall, double t, gr_error *err)
{
    double *p = rec(s, i);
    const int a = wall >> 1, up = wall & 1;
    FN(move)(p, t);
    double before = FN(kinetic_of)(s, i), vn = V(p)[a];
    double ew = s->cfg.wall_restitution;
    if (ew < 1.0 && s->cfg.contact_duration > 0.0 && t - s->ev[i].t_last < s->cfg.contact_duration)
        ew = 1.0;
    V(p)[a] = -V(p)[a];
    if (ew != 1.0)
        for (int k = 0; k < DIM; k++) V(p)[k] *= ew; /* law of reflection kept (2.22) */
    X(p)[a] = up ? s->cfg.hi[a] - R(p) : s->cfg.lo[a] + R(p);
    for (int k = 0; k < DIM; k++) {
        if (!isfinite(V(p)[k])) {
            gr_error_set(err, GR_ERR_NONFINITE, uid(s, i), -1, t, V(p)[k], "a velocity after a heated wall");
            return GR_ERR_NONFINITE;
        }
    }
    s->wall_impulse += s->mass[i] * (fabs(vn) + fabs(V(p)[a]));
    s->kinetic += FN(kinetic_of)(s, i) - before;
    s->wall++;
    s->ev[i].count++;
    s->ev[i].last = -2 - wall;
    if (FN(streak)(s, i, t)) {
        gr_error_set(err, GR_ERR_COLLAPSE, uid(s, i), -1, t, (double)GR_COLLAPSE_STREAK,
                     GR_XSTR(GR_COLLAPSE_STREAK) " successive collisions of one particle, "
                     "each within 1e-9 of a free-flight time of the previous");
        FN(predict)(s, i);
        return GR_ERR_COLLAPSE;
    }
    FN(predict)(s, i);
    return GR_OK;
}

static void FN(write_sample)(gr_edmd *s, gr_edmd_samples *smp, double ts)
{
    const int64_t k = smp->next;
    const size_t base = (size_t)k * s->n * DIM;
    double kin = 0.0, mom[DIM];
    for (int a = 0; a < DIM; a++) mom[a] = 0.0;
    for (int32_t i = 0; i < s->n; i++) {
        const double *p = rec(s, i);
        const double dt = ts - T(p), m = s->mass[i];
        const size_t out = base + (size_t)s->id_of[i] * DIM;
        for (int a = 0; a < DIM; a++) {
            double v = V(p)[a];
            if (smp->pos)
                smp->pos[out + a] = X(p)[a] + v * dt + (double)s->image[(size_t)i * DIM + a] * s->L[a];
            if (smp->vel) smp->vel[out + a] = v;
            mom[a] += m * v;
            kin += 0.5 * m * v * v;
        }
    }
    if (smp->kinetic) smp->kinetic[k] = kin;
    if (smp->momentum)
        for (int a = 0; a < DIM; a++) smp->momentum[(size_t)k * DIM + a] = mom[a];
    if (smp->pair) smp->pair[k] = s->pair;
    if (smp->wall) smp->wall[k] = s->wall;
    if (smp->virial) smp->virial[k] = s->virial;
    if (smp->wall_impulse) smp->wall_impulse[k] = s->wall_impulse;
    smp->next = k + 1;
}

static int FN(setup)(gr_edmd *s, gr_error *err)
{
    const int32_t n = s->n;
    for (int32_t i = 0; i < n; i++) {
        FN(file_in_cell)(s, i);
        if (!s->is_big[i]) cell_insert(s, i, FN(cell_of)(s, s->ev[i].c));
    }
    /* Overlaps of the big particles with everyone, O(N) each. */
    for (int32_t b = 0; b < s->n_big; b++) {
        const int32_t i = s->big[b];
        const double *p = rec(s, i);
        for (int32_t j = 0; j < n; j++) {
            if (j == i || (s->is_big[j] && j < i)) continue;
            const double *q = rec(s, j);
            double d2 = 0.0;
            for (int a = 0; a < DIM; a++) {
                double d = X(q)[a] - X(p)[a];
                if (s->cfg.periodic) d = nearest_image(d, s->L[a]);
                d2 += d * d;
            }
            double sigma = (R(p) + R(q)) * (1.0 - 1e-10);
            if (d2 < sigma * sigma) {
                int32_t lo = i < j ? i : j, hi = i < j ? j : i;
                gr_error_set(err, GR_ERR_OVERLAP, lo, hi, 0.0, R(p) + R(q) - sqrt(d2),
                             "in the initial configuration");
                return GR_ERR_OVERLAP;
            }
        }
    }
    /* Overlaps, O(N) through the cells.  Pairs touching to within a relative 1e-10 are
     * accepted (a configuration built at contact rounds either way); if they approach,
     * the engine collides them at once. */
    FN(nbr) nb[DIM == 3 ? 27 : 9];
    for (int32_t i = 0; i < n; i++) {
        const double *p = rec(s, i);
        int count = FN(neighbours)(s, s->ev[i].c, -1, 0, nb);
        for (int k = 0; k < count; k++) {
            for (int32_t j = s->head[nb[k].cell]; j >= 0; j = s->next[j]) {
                if (j <= i) continue;
                const double *q = rec(s, j);
                double d2 = 0.0;
                for (int a = 0; a < DIM; a++) {
                    double d = X(q)[a] + nb[k].shift[a] - X(p)[a];
                    d2 += d * d;
                }
                double sigma = (R(p) + R(q)) * (1.0 - 1e-10);
                if (d2 < sigma * sigma) {
                    gr_error_set(err, GR_ERR_OVERLAP, i, j, 0.0, R(p) + R(q) - sqrt(d2),
                                 "in the initial configuration");
                    return GR_ERR_OVERLAP;
                }
            }
        }
    }
    if (s->nl) {
        for (int32_t i = 0; i < n; i++) FN(set_centre)(s, i); /* the cells as above */
        for (int32_t i = 0; i < n; i++) {
            int status = FN(link_near)(s, i, 1, err);
            if (status != GR_OK) return status;
        }
    }
    int status = reorder(s);
    if (status != GR_OK) return status;
    for (int32_t i = 0; i < n; i++) FN(predict)(s, i);
    return GR_OK;
}

/* The time of the next sample due, +inf if none. */
static inline double FN(next_sample)(const gr_edmd_samples *smp)
{
    return smp && smp->next < smp->count ? smp->times[smp->next] : INFINITY;
}

static int FN(advance)(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err)
{
    const double t_stop = stop->t_stop;
    const int64_t n = s->n;
    const double collisions = stop->collisions_per_particle * (double)n;
    const double kinetic = stop->kinetic_energy * (double)n;
    /* events at one instant beyond this are a pile-up (every particle crossing a cell
     * wall at once, as a moving lattice does, is still well below it) */
    const int64_t pileup = 16 * n + 1000;
    /* Before this time no sample is due and the run does not stop for time: most events
     * then need one comparison for both. */
    double t_gate = fmin(FN(next_sample)(smp), t_stop);
    /* The collision and energy criteria change only with a collision; they are tested
     * after the first event of the call and after every collision. */
    int check = 1;
    for (int64_t k = 0;; k++) {
        if (k >= stop->max_events) return GR_STOP_BUDGET;
        if (s->scratch && s->events >= s->next_reorder) {
            int status = reorder(s);
            if (status != GR_OK) return status;
        }
        double te;
        const int32_t i = gr_cq_top(&s->queue, &te);
        if (te != te) {
            gr_error_set(err, GR_ERR_NONFINITE, uid(s, i), -1, s->t, te, "an event time");
            return GR_ERR_NONFINITE;
        }
        if (te >= t_gate) {
            while (smp && smp->next < smp->count && smp->times[smp->next] <= te &&
                   smp->times[smp->next] <= t_stop) {
                double ts = smp->times[smp->next];
                FN(write_sample)(s, smp, ts);
                set_clock(s, ts);
            }
            if (te > t_stop) {
                set_clock(s, t_stop);
                return GR_STOP_TIME;
            }
            if (te == INFINITY) return GR_STOP_IDLE;
            t_gate = fmin(FN(next_sample)(smp), t_stop);
        }
        if (te <= s->t_prev_event) {
            if (++s->same_instant > pileup) {
                gr_error_set(err, GR_ERR_COLLAPSE, uid(s, i), uid(s, s->ev[i].partner), te, (double)pileup,
                             "events pile up at one instant");
                return GR_ERR_COLLAPSE;
            }
        } else {
            s->same_instant = 0;
            s->t_prev_event = te;
        }
        set_clock(s, te);
        s->events++;
        gr_event *e = &s->ev[i];
        {
            int32_t h = gr_cq_hint(&s->queue);
            if (h >= 0) PREFETCH_PARTICLE(s, h);
            if (e->t_coll <= e->t_cross && e->partner >= 0) PREFETCH_PARTICLE(s, e->partner);
        }
        int status = GR_OK;
        if (e->t_cross < e->t_coll) {
            status = s->nl ? FN(do_rebuild)(s, i, te, err) : FN(do_cross)(s, i, te);
        } else if (e->partner >= 0) {
            if (s->ev[e->partner].count != e->pcount) { /* partner collided since: stale */
                s->invalid++;
                FN(move)(rec(s, i), te);
                FN(predict)(s, i);
                continue;
            }
            status = FN(do_pair)(s, i, e->partner, te, err);
            check = 1;
        } else {
            status = FN(do_wall)(s, i, -2 - e->partner, te, err);
            check = 1;
        }
        if (status != GR_OK) return status;
        if (check) {
            check = 0;
            if ((double)(2 * s->pair + s->wall) >= collisions) return GR_STOP_COLLISIONS;
            if (s->kinetic <= kinetic) return GR_STOP_ENERGY;
        }
    }
}

#undef X
#undef V
#undef T
#undef R
#undef PREFETCH_PARTICLE
