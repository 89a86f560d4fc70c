/* flight.h -- the free-flight seam: how a particle moves between events, and everything
 * that follows from it (where it is after a time, when two particles touch, when one
 * reaches a cell face, a wall or the edge of its neighbour shell, what the kinetic energy
 * integrates to over a flight).  The event loop, its searches, the AVX2 scan, the samples
 * and the clock call these and nothing else for motion: they write no straight line of
 * their own.
 *
 * A dynamics is a compile-time constant `dyn` (GR_FLIGHT_*), passed like the dimension:
 * edmd.c compiles its loop once per (dim, law, dynamics) -- advance_3d, advance_3d_law,
 * ... -- and every function here is inlined with `dyn` constant, so a switch on it costs
 * nothing and a scene pays only for its own dynamics.  Constant velocity
 * (GR_FLIGHT_LINEAR) is the only one today.
 *
 * What a new dynamics (say gravity: x(t) = x + v t + g t^2 / 2, v(t) = v + g t) provides,
 * as one more case in each function below, and one more advance_* in edmd.c (with its
 * choice in gr_edmd_advance, from a config field):
 *  - fl_move, fl_at, fl_vel_at: position and velocity after dt (a record keeps x and v
 *    at its own clock; velocities then change between events too);
 *  - fl_sep (and GR_FL_SEP for the AVX2 lanes), fl_relvel, fl_pair_beats: the pair's
 *    separation at i's clock and its relative motion.  Under a uniform field the
 *    relative motion stays a straight line (g cancels), so gravity changes fl_sep only
 *    (q's extrapolation gains g dtj^2 / 2) and keeps the quadratic contact solver;
 *  - fl_cross_time, fl_wall_time, fl_exit_time: a cell face, a wall, the shell's
 *    sphere.  Under gravity these become quadratics in dt (a particle thrown up may fall
 *    back through the face below: the face hit is the seam's answer, not the sign of v);
 *  - fl_kinetic_integral: the integral of the total kinetic energy over a flight, for the
 *    pressure.  With constant velocity it changes only at collisions; under gravity it
 *    changes in flight (d/dt = g . total momentum) and the clock integrates that.
 * The AVX2 scan (scan_avx2.h) is written for straight lines through GR_FL_SEP; a dynamics
 * whose GR_FL_SEP it cannot use runs the plain scan (edmd.c, predict).
 *
 * Each function keeps the order of operations the loop had when it wrote the straight
 * lines out (the golden outputs are bit for bit): x + v dt, ((q + vq dtj) - p). */
#ifndef GR_FLIGHT_H
#define GR_FLIGHT_H

#include <math.h>
#include <stdint.h>

#include "collide.h"
#include "common.h"

enum {
    GR_FLIGHT_LINEAR = 0 /* constant velocity between events */
};

/* The scalar operations, for the forms below that the AVX2 lanes share (scan_avx2.h
 * passes _mm256_add_pd and friends). */
#define GR_FL_ADD(a, b) ((a) + (b))
#define GR_FL_SUB(a, b) ((a) - (b))
#define GR_FL_MUL(a, b) ((a) * (b))

/* Position after dt from x with velocity v, in operations add and mul. */
#define GR_FL_AT(add, mul, x, v, dt) add(x, mul(v, dt))
/* One axis of the separation q - p of a partner q seen from p, q's record (position q,
 * velocity vq) brought dtj = t_p - t_q forward to p's clock. */
#define GR_FL_SEP(add, sub, mul, q, vq, dtj, p) sub(GR_FL_AT(add, mul, q, vq, dtj), p)

/* One coordinate after dt. */
static inline double fl_at(int dyn, double x, double v, double dt)
{
    (void)dyn;
    return GR_FL_AT(GR_FL_ADD, GR_FL_MUL, x, v, dt);
}

/* One velocity component after dt. */
static inline double fl_vel_at(int dyn, double v, double dt)
{
    (void)dyn;
    (void)dt;
    return v;
}

/* Advance a particle (position x[dim], velocity v[dim], both at its own clock *t_own) to
 * time t, and its clock with it. */
static inline void fl_move(int dyn, int dim, double *x, double *v, double *t_own, double t)
{
    double dt = t - *t_own;
    for (int a = 0; a < dim; a++) x[a] += v[a] * dt;
    (void)dyn;
    *t_own = t;
}

/* One axis of the separation of q from p at p's clock (see GR_FL_SEP). */
static inline double fl_sep(int dyn, double q, double vq, double dtj, double p)
{
    (void)dyn;
    return GR_FL_SEP(GR_FL_ADD, GR_FL_SUB, GR_FL_MUL, q, vq, dtj, p);
}

/* One axis of the relative velocity of q seen from p. */
static inline double fl_relvel(int dyn, double vq, double vp)
{
    (void)dyn;
    return vq - vp;
}

/* Whether the pair with separation dr and relative velocity dv (fl_sep, fl_relvel)
 * touches at contact distance sigma before `horizon`; *dt then the time (collide.h). */
static inline int fl_pair_beats(int dyn, int dim, const double *dr, const double *dv,
                                double sigma, double horizon, double *dt)
{
    (void)dyn;
    return gr_pair_beats(dim, dr, dv, sigma, horizon, dt);
}

/* The time from x, velocity v, to the face of cell c (width w, grid starting at lo)
 * that the particle reaches: *up 1 for the upper face, 0 the lower; *moving 0 if it
 * reaches neither (the result is then not a time).  Never negative: rounding may leave
 * a particle a hair past the face it just crossed.  Without branches on the sign of v
 * (it changes from event to event at random: edmd.c, predict_cross_in). */
static GR_ALWAYS_INLINE double fl_cross_time(int dyn, double x, double v, double lo, int32_t c,
                                             double w, int *up, int *moving)
{
    (void)dyn;
    *up = v > 0.0;
    *moving = v != 0.0;
    const double bound = lo + (c + *up) * w;
    double dt = (bound - x) / (v != 0.0 ? v : 1.0);
    return dt < 0.0 ? 0.0 : dt;
}

/* The time from x, velocity v, until the centre reaches lo_stop or hi_stop (the walls
 * less the radius): returns 1 for hi_stop, 0 for lo_stop, -1 for neither (*dt then
 * unset).  *dt may be negative by rounding (the caller clamps). */
static inline int fl_wall_time(int dyn, double x, double v, double lo_stop, double hi_stop,
                               double *dt)
{
    (void)dyn;
    if (v > 0.0) *dt = (hi_stop - x) / v;
    else if (v < 0.0) *dt = (lo_stop - x) / v;
    else return -1;
    return v > 0.0;
}

/* When a particle at x with velocity v leaves the sphere of squared radius exit2 about
 * `centre` (neighbour lists' shell): the time from now, +inf if never. */
static inline double fl_exit_time(int dyn, int dim, const double *x, const double *v,
                                  const double *centre, double exit2)
{
    (void)dyn;
    double a = 0.0, b = 0.0, c = -exit2;
    for (int k = 0; k < dim; k++) {
        const double d = x[k] - centre[k];
        a += v[k] * v[k];
        b += d * v[k];
        c += d * d;
    }
    /* the larger root of a dt^2 + 2 b dt + c = 0 with c < 0, in the form without
     * cancellation; c >= 0 is a hair outside by rounding: leave now */
    if (!(a > 0.0)) return INFINITY;
    if (c >= 0.0) return 0.0;
    const double q = sqrt(b * b - a * c);
    return b > 0.0 ? -c / (b + q) : (q - b) / a;
}

/* The kinetic energy of one particle of mass m, velocity v. */
static inline double fl_kinetic(int dyn, int dim, double m, const double *v)
{
    (void)dyn;
    double v2 = 0.0;
    for (int a = 0; a < dim; a++) v2 += v[a] * v[a];
    return 0.5 * m * v2;
}

/* The integral over a flight of dt of the total kinetic energy, `kinetic` at its start:
 * constant between collisions with constant velocity. */
static inline double fl_kinetic_integral(int dyn, double kinetic, double dt)
{
    (void)dyn;
    return kinetic * dt;
}

#endif
