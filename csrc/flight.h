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
 * (GR_FLIGHT_LINEAR) and uniform gravity (GR_FLIGHT_GRAVITY) are the two so far.
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
 *    changes in flight (d/dt = g . total momentum) and the clock integrates that;
 *  - and outside this file, stress.h's flight of the kinetic tensor sum m v_a v_b
 *    (stress_kinetic_at, stress_sync), for Simulation(stress=True), or a refusal of the
 *    tensor with the new dynamics in validate.c.
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
    GR_FLIGHT_LINEAR = 0, /* constant velocity between events */
    GR_FLIGHT_GRAVITY = 1 /* uniform acceleration g: x + v t + g t^2 / 2, v + g t */
};

/* Every function takes the acceleration: g (one axis) or g[dim]; constant velocity
 * ignores it, so its inlined code does not even load it. */

/* A function compiled once, called rather than inlined (unused: units that do not call
 * it are not warned about it). */
#if defined(__GNUC__) || defined(__clang__)
#define GR_NOINLINE __attribute__((noinline, unused))
#else
#define GR_NOINLINE
#endif

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

/* One coordinate after dt (acceleration g along it). */
static inline double fl_at(int dyn, double x, double v, double g, double dt)
{
    if (dyn == GR_FLIGHT_GRAVITY) return x + (v + 0.5 * g * dt) * dt;
    (void)g;
    return GR_FL_AT(GR_FL_ADD, GR_FL_MUL, x, v, dt);
}

/* One velocity component after dt. */
static inline double fl_vel_at(int dyn, double v, double g, double dt)
{
    if (dyn == GR_FLIGHT_GRAVITY) return v + g * dt;
    (void)g;
    (void)dt;
    return v;
}

/* Advance a particle (position x[dim], velocity v[dim], both at its own clock *t_own) to
 * time t, and its clock with it. */
static inline void fl_move(int dyn, int dim, double *x, double *v, const double *g,
                           double *t_own, double t)
{
    double dt = t - *t_own;
    if (dyn == GR_FLIGHT_GRAVITY) {
        for (int a = 0; a < dim; a++) {
            x[a] = fl_at(dyn, x[a], v[a], g[a], dt);
            v[a] = fl_vel_at(dyn, v[a], g[a], dt);
        }
    } else {
        for (int a = 0; a < dim; a++) x[a] += v[a] * dt;
    }
    (void)g;
    *t_own = t;
}

/* One axis of the separation of q from p at p's clock (see GR_FL_SEP). */
static inline double fl_sep(int dyn, double q, double vq, double g, double dtj, double p)
{
    if (dyn == GR_FLIGHT_GRAVITY) return fl_at(dyn, q, vq, g, dtj) - p;
    (void)g;
    return GR_FL_SEP(GR_FL_ADD, GR_FL_SUB, GR_FL_MUL, q, vq, dtj, p);
}

/* One axis of the relative velocity of q seen from p at p's clock (q's record is dtj
 * older: under gravity its velocity gains g dtj; p's and q's share g, so the relative
 * motion from then on is a straight line). */
static inline double fl_relvel(int dyn, double vq, double vp, double g, double dtj)
{
    if (dyn == GR_FLIGHT_GRAVITY) return fl_vel_at(dyn, vq, g, dtj) - vp;
    (void)g;
    (void)dtj;
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

/* Gravity's longer branches are functions of their own, not inlined (GR_NOINLINE): in
 * the constant-velocity loops they are dead code, but a larger body would change what
 * the compiler inlines there, and with it the plain loop's instructions an event. */

/* Under gravity: the time from now until x + v t + a t^2 (a = g/2 != 0) crosses the
 * level x + d upwards (increasing), or +inf if it never does from now on.  Of the two
 * roots of a t^2 + v t - d = 0, the one with dx/dt = +sqrt(D) > 0 (D = v^2 + 4 a d) is
 * the upward crossing: t = (sqrt D - v) / 2a = 2d / (v + sqrt D), each form taken where
 * it adds numbers of one sign (no cancellation at grazing, where D ~ 0, nor for small d).
 * A particle at or past the level (d <= 0, by rounding) and moving up crosses now.  A
 * parabola crosses a level upwards at most once, so a root in the past means never:
 * the apex below the level (D < 0) too.  The downward crossing is this one mirrored. */
static inline double fl_up_time(double d, double v, double a)
{
    if (d <= 0.0 && v > 0.0) return 0.0;
    const double disc = v * v + 4.0 * a * d;
    if (!(disc >= 0.0)) return INFINITY;
    const double sq = sqrt(disc);
    if (v > 0.0) return 2.0 * d / (v + sq); /* d > 0 here: a time > 0 */
    return a > 0.0 ? (sq - v) / (2.0 * a) : INFINITY; /* v <= 0: only a rising pull lifts it */
}

/* The first of x's crossings, under acceleration g != 0, of the levels lo downwards and
 * hi upwards (lo <= hi; a cell's faces, or the walls less the radius): its time, with
 * *up 1 for hi and 0 for lo.  One of them is always reached (the pull turns any flight
 * towards one), unless the time overflows: *reaches then 0 (the result is not a time). */
static GR_NOINLINE double fl_level_pair(double x, double v, double g, double lo, double hi,
                                        int *up, int *reaches)
{
    const double a = 0.5 * g;
    const double t_hi = fl_up_time(hi - x, v, a), t_lo = fl_up_time(x - lo, -v, -a);
    *up = t_hi < t_lo;
    const double t = *up ? t_hi : t_lo;
    *reaches = t < INFINITY;
    return t;
}

/* The time from x, velocity v, to the face of cell c (width w, grid starting at lo)
 * that the particle reaches: *up 1 for the upper face, 0 the lower; *moving 0 if it
 * reaches neither (the result is then not a time).  Never negative: rounding may leave
 * a particle a hair past the face it just crossed.  Without branches on the sign of v
 * (it changes from event to event at random: edmd.c, predict_cross_in). */
static GR_ALWAYS_INLINE double fl_cross_time(int dyn, double x, double v, double g, double lo,
                                             int32_t c, double w, int *up, int *moving)
{
    if (dyn == GR_FLIGHT_GRAVITY && g != 0.0) {
        const double face = lo + c * w;
        return fl_level_pair(x, v, g, face, face + w, up, moving);
    }
    (void)g;
    *up = v > 0.0;
    *moving = v != 0.0;
    const double bound = lo + (c + *up) * w;
    double dt = (bound - x) / (v != 0.0 ? v : 1.0);
    return dt < 0.0 ? 0.0 : dt;
}

/* The time from x, velocity v, until the centre reaches lo_stop or hi_stop (the walls
 * less the radius): returns 1 for hi_stop, 0 for lo_stop, -1 for neither (*dt then
 * unset).  *dt may be negative by rounding (the caller clamps). */
static inline int fl_wall_time(int dyn, double x, double v, double g, double lo_stop,
                               double hi_stop, double *dt)
{
    if (dyn == GR_FLIGHT_GRAVITY && g != 0.0) {
        int up, reaches;
        *dt = fl_level_pair(x, v, g, lo_stop, hi_stop, &up, &reaches);
        return reaches ? up : -1;
    }
    (void)g;
    if (v > 0.0) *dt = (hi_stop - x) / v;
    else if (v < 0.0) *dt = (lo_stop - x) / v;
    else return -1;
    return v > 0.0;
}

/* Under gravity: |d + v t + g t^2/2| <= |d| + |v| t + |g| t^2/2, and the time at which
 * that bound reaches the shell's radius is a lower bound of the exit (the exact one is a
 * root of a quartic); an early exit only rebuilds the list early.  At a rebuild d = 0,
 * and along a straight line the bound is the exit. */
static GR_NOINLINE double fl_exit_time_gravity(int dim, const double *x, const double *v,
                                               const double *g, const double *centre,
                                               double exit2)
{
    double d2 = 0.0, v2 = 0.0, g2 = 0.0;
    for (int k = 0; k < dim; k++) {
        const double dk = x[k] - centre[k];
        d2 += dk * dk;
        v2 += v[k] * v[k];
        g2 += g[k] * g[k];
    }
    const double room = sqrt(exit2) - sqrt(d2), speed = sqrt(v2), half_g = 0.5 * sqrt(g2);
    if (!(room > 0.0)) return 0.0;
    /* the positive root of half_g t^2 + speed t - room = 0, without cancellation */
    return 2.0 * room / (speed + sqrt(speed * speed + 4.0 * half_g * room));
}

/* When a particle at x with velocity v leaves the sphere of squared radius exit2 about
 * `centre` (neighbour lists' shell): the time from now, +inf if never. */
static inline double fl_exit_time(int dyn, int dim, const double *x, const double *v,
                                  const double *g, const double *centre, double exit2)
{
    if (dyn == GR_FLIGHT_GRAVITY) return fl_exit_time_gravity(dim, x, v, g, centre, exit2);
    (void)g;
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

/* The kinetic energy of one particle of mass m, velocity v (at the particle's clock). */
static inline double fl_kinetic(int dyn, int dim, double m, const double *v)
{
    (void)dyn;
    double v2 = 0.0;
    for (int a = 0; a < dim; a++) v2 += v[a] * v[a];
    return 0.5 * m * v2;
}

/* The integral over a flight of dt of the total kinetic energy, *kinetic at its start:
 * constant between collisions with constant velocity.  Under gravity the energy grows as
 * d/dt K = g . P and the total momentum P (mass M) as dP/dt = M g between collisions, so
 * K(t) = K + g.P t + M g^2 t^2 / 2, whose integral this returns, and *kinetic and
 * momentum[dim] are brought to the flight's end. */
static GR_NOINLINE double fl_kinetic_integral_gravity(int dim, double *kinetic,
                                                      double *momentum, double mass,
                                                      const double *g, double dt)
{
    double gp = 0.0, g2 = 0.0;
    for (int a = 0; a < dim; a++) {
        gp += g[a] * momentum[a];
        g2 += g[a] * g[a];
        momentum[a] += mass * g[a] * dt;
    }
    const double k = *kinetic;
    *kinetic = k + (gp + 0.5 * mass * g2 * dt) * dt;
    return (k + (0.5 * gp + mass * g2 * dt / 6.0) * dt) * dt;
}

static inline double fl_kinetic_integral(int dyn, int dim, double *kinetic, double *momentum,
                                         double mass, const double *g, double dt)
{
    if (dyn == GR_FLIGHT_GRAVITY)
        return fl_kinetic_integral_gravity(dim, kinetic, momentum, mass, g, dt);
    (void)dim;
    (void)momentum;
    (void)mass;
    (void)g;
    return *kinetic * dt;
}

#endif
