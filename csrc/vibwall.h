/* vibwall.h -- a vibrating wall: one wall of a walled box moving along its axis, and the
 * exact time a particle in free flight first touches it.
 *
 * The wall (gr_vibwall in edmd.h) is the face of axis `axis` on side `side` (0 the face at
 * lo, 1 at hi).  Its position is
 *     X(t) = c + A f(omega t + phase),   c = lo + A (side 0) or hi - A (side 1),
 * with f = sin (GR_WAVE_SINE) or the triangle wave of the same period and phase (GR_WAVE_
 * TRIANGLE: f(theta) = (2/pi) asin(sin theta), speed +-(2/pi) A omega).  So the wall sweeps
 * [lo, lo + 2A] (or [hi - 2A, hi]) and never leaves the box or its cell grid; validate.c
 * refuses a box too thin for a particle between the wall at its innermost and the opposite
 * face.  The wall's velocity is U(t) = A omega f'(omega t + phase).
 *
 * The hit time.  With the particle's normal coordinate x(tau) and velocity v(tau) after a
 * time tau from its clock (flight.h: fl_at / fl_vel_at), the gap between the particle's
 * surface and the wall is
 *     h(tau) = sigma (x(tau) - X(t0 + tau)) - r,   sigma = +1 (side 0), -1 (side 1),
 * its rate h' = sigma (v(tau) - U(t0 + tau)), and |h''| <= K = |a_n| + A omega^2 (sine;
 * 0 within a linear piece of the triangle, whose steps stop at its kinks).  From any tau
 * with h > 0 the first root of h + h' s - K s^2 / 2 is a lower bound on the next contact
 * (h stays above that parabola), so stepping by it never passes a hit; near a transversal
 * root the steps converge quadratically (they are Newton steps with a safety margin), and
 * the search ends when a step no longer moves the absolute time (full precision) or the
 * gap is no longer positive while approaching.  A particle outside the wall's band of reach
 * is predicted to reach the band's face (fl_wall_time: one division), where an event that
 * is no contact (vw_touching) starts the search: most particles are far from the wall, and
 * their predictions then cost what a fixed wall's do.  Grazing: where the gap is
 * within the rounding of positions (tol) and not closing, the search steps on by at least
 * sqrt(2 tol / K), in which the gap cannot fall below -tol: a touch shallower than the
 * rounding of the coordinates is not a hit; any deeper one is found.
 *
 * The contract with the dynamics (flight.h).  The search uses only fl_at, fl_vel_at (the
 * normal coordinate and velocity after tau), fl_wall_time (reaching a plane: the band's
 * edge; it is given +-inf as the stop on the side it does not ask about, which must come
 * out as never reached, and it must answer the first crossing of the plane asked about,
 * from either side) and vw_normal_accel below (a bound on |dv/dtau| along the axis).  Constant velocity:
 * 0.  A uniform field g adds |g[axis]| there and needs nothing else: the same search then
 * times a vibrating floor under gravity (the parabola bound holds for any |h''| <= K). */
#ifndef GR_VIBWALL_H
#define GR_VIBWALL_H

#include <float.h>
#include <math.h>

#include "edmd.h"
#include "flight.h"

#define GR_VW_PI 3.14159265358979323846

/* A bound on the particle's acceleration along axis a under dynamics dyn. */
static inline double vw_normal_accel(int dyn, double g)
{
    return dyn == GR_FLIGHT_GRAVITY ? fabs(g) : 0.0;
}

/* The wall's phase omega t + phase at absolute time t. */
static inline double vw_theta(const gr_vibwall *w, double t) { return w->omega * t + w->phase; }

/* The triangle wave's position in its cycle: theta / 2 pi modulo 1, in [0, 1). */
static inline double vw_cycle(double theta)
{
    const double u = theta / (2.0 * GR_VW_PI);
    const double f = u - floor(u);
    return f < 1.0 ? f : 0.0;
}

/* f(theta): sin, or the triangle wave with its peaks where sin has them. */
static inline double vw_wave(const gr_vibwall *w, double theta)
{
    if (w->waveform == GR_WAVE_SINE) return sin(theta);
    const double u = vw_cycle(theta);
    return u < 0.25 ? 4.0 * u : u < 0.75 ? 2.0 - 4.0 * u : 4.0 * u - 4.0;
}

/* The triangle wave's cycle position for its slope and kinks: within GR_VW_KINK (of a
 * cycle) before a kink counts as past it.  The search steps to a kink and must then see
 * the next piece, where rounding may leave it a hair short. */
#define GR_VW_KINK 1e-12
static inline double vw_piece(double theta)
{
    const double u = vw_cycle(theta);
    return (0.25 - u >= 0.0 && 0.25 - u < GR_VW_KINK) || (0.75 - u >= 0.0 && 0.75 - u < GR_VW_KINK)
               ? u + GR_VW_KINK
               : u;
}

/* f'(theta) (the triangle's slope of the piece ahead at a kink). */
static inline double vw_wave_slope(const gr_vibwall *w, double theta)
{
    if (w->waveform == GR_WAVE_SINE) return cos(theta);
    const double u = vw_piece(theta);
    return (u < 0.25 || u >= 0.75) ? 2.0 / GR_VW_PI : -2.0 / GR_VW_PI;
}

/* The wall's rest position (the centre of its sweep). */
static inline double vw_centre(const gr_vibwall *w, double lo, double hi)
{
    return w->side ? hi - w->amplitude : lo + w->amplitude;
}

/* The wall's position X(t) and velocity U(t). */
static inline double vw_position(const gr_vibwall *w, double lo, double hi, double t)
{
    return vw_centre(w, lo, hi) + w->amplitude * vw_wave(w, vw_theta(w, t));
}

static inline double vw_velocity(const gr_vibwall *w, double t)
{
    return w->amplitude * w->omega * vw_wave_slope(w, vw_theta(w, t));
}

/* The time from t to the triangle wave's next kink (where its velocity flips; one within
 * GR_VW_KINK counts as passed, as for vw_wave_slope); +inf for the sine. */
static inline double vw_to_kink(const gr_vibwall *w, double t)
{
    if (w->waveform == GR_WAVE_SINE) return INFINITY;
    const double u = vw_piece(vw_theta(w, t));
    const double next = u < 0.25 ? 0.25 : u < 0.75 ? 0.75 : 1.25;
    return (next - u) * (2.0 * GR_VW_PI) / w->omega;
}

/* The float64 resolution of the wall's phase at time t: omega times the spacing of doubles
 * at t.  The engine refuses to run where it passes GR_VIB_PHASE_RESOLUTION (edmd.c). */
#define GR_VIB_PHASE_RESOLUTION 0x1p-26
static inline double vw_phase_resolution(const gr_vibwall *w, double t)
{
    return w->omega * (nextafter(fabs(t), INFINITY) - fabs(t));
}

/* The rounding of a gap to the wall near time t: of the coordinates and of the wall's
 * position (A times the rounding of its phase). */
static inline double vw_tol(const gr_vibwall *w, double lo, double hi, double t)
{
    return 16.0 * DBL_EPSILON * (fabs(lo) + fabs(hi) + w->amplitude * (1.0 + fabs(vw_theta(w, t))));
}

/* Whether a particle (coordinate x, velocity v along the wall's axis, radius r, at time t)
 * whose predicted wall event is now touches the wall: the search (vw_hit_time) predicts
 * contacts and, for a particle outside the wall's band, the time it enters the band, where
 * the gap is wider than a contact's rounding (the coordinates', and the closing speed times
 * the time's). */
static inline int vw_touching(const gr_vibwall *w, double lo, double hi, double t, double x,
                              double v, double r)
{
    const double sigma = w->side ? -1.0 : 1.0, U = vw_velocity(w, t);
    const double h = sigma * (x - vw_position(w, lo, hi, t)) - r;
    const double ulp = nextafter(fabs(t), INFINITY) - fabs(t);
    return h <= vw_tol(w, lo, hi, t) + 4.0 * (fabs(v) + fabs(U)) * ulp;
}

/* Iterations of the search before it gives up and returns where it stands (an event there
 * finds the particle not approaching and searches again from that later time: progress,
 * never a missed hit).  Reached only in pathological cases: a prediction takes a few
 * steps per wall period it spans, and it spans at most about one before a hit or leaving
 * the band. */
#define GR_VIB_MAX_STEPS 4096

/* The time from the particle's clock t0 (normal coordinate x0, velocity v0 along the
 * wall's axis a, radius r) to its first contact with the vibrating wall w of the box
 * [lo, hi] along a, approaching it, or the time it enters the wall's band if it is outside
 * (vw_touching tells the two apart); +inf if there is neither. */
static inline double vw_hit_time(const gr_vibwall *w, int dyn, double g, double lo, double hi,
                                 double t0, double x0, double v0, double r)
{
    const double sigma = w->side ? -1.0 : 1.0;
    const double A = w->amplitude;
    /* the innermost face of the band the wall sweeps, less the radius: the centre plane
     * beyond which no contact is possible */
    const double band = w->side ? hi - 2.0 * A - r : lo + 2.0 * A + r;
    const double K = vw_normal_accel(dyn, g) +
                     (w->waveform == GR_WAVE_SINE ? A * w->omega * w->omega : 0.0);
    const double tol = vw_tol(w, lo, hi, t0);
    const double min_step = K > 0.0 ? sqrt(2.0 * tol / K) : 0.0;
    double tau = 0.0;
    for (int it = 0; it < GR_VIB_MAX_STEPS; it++) {
        const double x = fl_at(dyn, x0, v0, g, tau), v = fl_vel_at(dyn, v0, g, tau);
        /* outside the band (by more than rounding: a particle flown to its face is in it):
         * fly to its face */
        if (sigma * (x - band) > tol) {
            double dt = INFINITY;
            const int which = w->side ? fl_wall_time(dyn, x, v, g, -INFINITY, band, &dt)
                                      : fl_wall_time(dyn, x, v, g, band, INFINITY, &dt);
            if (which != w->side || !(dt < INFINITY)) return INFINITY;
            /* the time it enters the band: an event there (vw_touching says it is no
             * contact) starts the exact search, so that a particle far from the wall costs
             * one division per prediction, not a search */
            if (dt > 0.0 && t0 + (tau + dt) > t0 + tau) return tau + dt;
        }
        const double t = t0 + tau;
        const double h = sigma * (x - vw_position(w, lo, hi, t)) - r;
        const double hd = sigma * (v - vw_velocity(w, t));
        if (hd < 0.0 && h <= 0.0) return tau; /* touching (or a hair past) and closing */
        double s;
        if (h > 0.0) {
            /* the first root of h + hd s - K s^2 / 2, in the form without cancellation */
            const double q = sqrt(hd * hd + 2.0 * K * h);
            s = hd < 0.0 ? 2.0 * h / (q - hd) : (K > 0.0 ? (hd + q) / K : INFINITY);
        } else {
            /* behind the wall by rounding and not closing: the gap closes again at the
             * earliest after 2 hd / K */
            s = K > 0.0 ? 2.0 * hd / K : INFINITY;
        }
        if (h <= tol && hd >= 0.0 && s < min_step) s = min_step; /* grazing: step on */
        const double kink = vw_to_kink(w, t);
        if (s > kink) s = kink;
        if (!(s < INFINITY)) return INFINITY; /* no curvature and not closing: never */
        if (!(t0 + (tau + s) > t)) {
            /* the step no longer moves the time: the contact is here, to full precision
             * (closing), or a tangency at rounding's scale (then step by one ulp) */
            if (hd < 0.0) return tau;
            s = nextafter(t, INFINITY) - t0 - tau;
            if (!(s > 0.0)) s = nextafter(tau, INFINITY) - tau;
        }
        tau += s;
    }
    return tau;
}

#endif
