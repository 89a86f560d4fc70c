/* stress.h -- the stress (pressure) tensor's accumulators, kept only when the engine was
 * built with cfg.stress = 1 (a d x d tensor per collision costs some 100 instructions, a
 * tenth of an event: the plain loop pays one untaken branch per collision for it).
 *
 * The pressure tensor over a window [t0, t1] of a box of volume V is
 *     P_ab = ( int_t0^t1 K_ab dt + W_ab(t1) - W_ab(t0) ) / (V (t1 - t0)),
 *     K_ab = sum_i m_i v_ia v_ib                  (the kinetic tensor, instantaneous),
 *     W_ab = sum over pair collisions of r_a dp_b  (r = x_j - x_i at contact, the
 *            separation the collision used; dp = the momentum j received),
 * Irving & Kirkwood's (J. Chem. Phys. 18, 817 (1950)) kinetic plus collisional parts for
 * instantaneous impulses (Allen & Tildesley, Computer Simulation of Liquids, 2nd ed.,
 * section 2.4 and 3.7.2).  Its trace over d is the scalar pressure granular already
 * computes (2 int E_kin dt + virial, Trajectory.pressure) to rounding: trace(W) is
 * r . dp summed in another order than the virial, trace(int K) twice the kinetic-energy
 * integral kept by other differences.  Wall impulses do not enter, as they do not enter
 * the scalar pressure (its walled V is the volume the centres reach).
 *
 * The kinetic tensor is kept by differences at each collision (the only moments a velocity
 * changes under constant-velocity flight), with its integral brought up to the time of the
 * last change (stress_t): the integral to any later t is st_kin_time + K (t - stress_t),
 * exact up to rounding.  K is summed anew from the velocities whenever s->kinetic is
 * (edmd.c, at fixed collision counts), so checkpoints continue it bit for bit.  Under
 * gravity K changes in flight too, by a polynomial the sync integrates exactly (below). */
#ifndef GR_STRESS_H
#define GR_STRESS_H

#include "engine.h"

/* ---- a sheared box (Lees-Edwards, boundary.h) ----
 * There the kinetic tensor is that of the peculiar velocities, V = v - g (y - y_c) e_x
 * (g the shear rate, y the position in the box, y_c its centre), which change in flight:
 * dV/dt = -g v_y e_x = -g V_y e_x.  So K_ab = sum m V_a V_b obeys, between events,
 *     dK_ab/dt = -g (delta_ax K_yb + delta_bx K_ay),
 * whose solution is polynomial in the time s since stress_t (x = 0, y = 1):
 *     K_yy, K_yz, K_zz        constant,
 *     K_xb(s) = K_xb - g K_yb s  and  K_ax(s) = K_ax - g K_ay s   (a, b != x),
 *     K_xx(s) = K_xx - g (K_xy + K_yx) s + g^2 K_yy s^2,
 * and its integral follows exactly (stress_le_at).  Kept this way, K is the peculiar
 * tensor itself: no flow energy to cancel against.  A collision changes it by
 * m (V'V' - V V) for each particle (V from the box velocity and position, or equally from
 * an image's: the image's velocity and flow differ by the same u); a face crossing not at
 * all, as V is continuous through it (v_x and y jump together by -+u and -+L_y). */

/* K and its integral advanced by s from k (at stress_t) in a sheared box with rate g. */
static inline void stress_le_at(int dim, double g, const double *k, double s, double *k_out,
                                double *int_out)
{
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++) {
            const int c = a * dim + b;
            double k1 = 0.0, k2 = 0.0; /* K_ab(s) = k[c] + k1 s + k2 s^2 */
            if (a == 0 && b == 0) {
                k1 = -g * (k[1] + k[dim]);
                k2 = g * g * k[dim + 1];
            } else if (a == 0) {
                k1 = -g * k[dim + b];
            } else if (b == 0) {
                k1 = -g * k[a * dim + 1];
            }
            k_out[c] = k[c] + (k1 + k2 * s) * s;
            int_out[c] = (k[c] + (0.5 * k1 + k2 * s / 3.0) * s) * s;
        }
}

/* The peculiar velocity of particle i (record p, clock at its own time) at time t.  Straight
 * flight (GR_FLIGHT_LINEAR, the polynomials above assume it too): a dynamics with forces
 * must bring its own flight of y and v here, or be refused with shear. */
static inline void stress_le_peculiar(const gr_edmd *s, int dim, const double *p, double t,
                                      double *V)
{
    const double *v = VEL(p, dim);
    const double y = p[1] + v[1] * (t - TIME(p, dim)) - 0.5 * (s->cfg.lo[1] + s->cfg.hi[1]);
    for (int a = 0; a < dim; a++) V[a] = v[a];
    V[0] -= s->cfg.shear_rate * y;
}

/* Bring a sheared box's kinetic tensor and its integral to time t (>= stress_t). */
static void stress_le_sync(gr_edmd *s, int dim, double t)
{
    double k[9], kt[9];
    stress_le_at(dim, s->cfg.shear_rate, s->st_kin, t - s->stress_t, k, kt);
    for (int c = 0; c < dim * dim; c++) {
        s->st_kin[c] = k[c];
        s->st_kin_time[c] += kt[c];
    }
    s->stress_t = t;
}

/* ---- under uniform gravity (flight.h, GR_FLIGHT_GRAVITY) ----
 * Every velocity is v + g tau after a flight of tau, so between collisions
 *     K_ab(tau) = sum m (v_a + g_a tau)(v_b + g_b tau)
 *               = K_ab + (P_a g_b + g_a P_b) tau + M g_a g_b tau^2,
 * P the total momentum and M the total mass at stress_t, and its integral over the flight
 * is exact in closed form:
 *     K_ab tau + (P_a g_b + g_a P_b) tau^2 / 2 + M g_a g_b tau^3 / 3.
 * The engine keeps the total momentum at its own clock s->t (s->momentum, flight.h's
 * fl_kinetic_integral), and nothing but gravity changes it between stress_t and s->t: a
 * wall's impulse syncs the tensor first (stress_wall) and pair collisions and kicks keep
 * it.  So P(stress_t) = P(s->t) - M g (s->t - stress_t). */

/* Whether the system flies under gravity (engine.h dynamics_of): a test made only where
 * the tensor is kept, never in the plain loop without it. */
static inline int stress_gravity(const gr_edmd *s)
{
    return dynamics_of(s) == GR_FLIGHT_GRAVITY;
}

/* K and its integral advanced by tau from st_kin (at stress_t) under gravity. */
static inline void stress_gravity_at(const gr_edmd *s, int dim, double tau, double *k_out,
                                     double *int_out)
{
    const double *g = s->cfg.gravity, M = s->mass_total, back = s->t - s->stress_t;
    double P[3];
    for (int a = 0; a < dim; a++) P[a] = s->momentum[a] - M * g[a] * back;
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++) {
            const int c = a * dim + b;
            const double k = s->st_kin[c], k1 = P[a] * g[b] + g[a] * P[b], k2 = M * g[a] * g[b];
            k_out[c] = k + (k1 + k2 * tau) * tau;
            int_out[c] = (k + (0.5 * k1 + k2 * tau / 3.0) * tau) * tau;
        }
}

/* Bring the kinetic tensor and its integral to time t (>= stress_t) under gravity. */
static void stress_gravity_sync(gr_edmd *s, int dim, double t)
{
    double k[9], kt[9];
    stress_gravity_at(s, dim, t - s->stress_t, k, kt);
    for (int c = 0; c < dim * dim; c++) {
        s->st_kin[c] = k[c];
        s->st_kin_time[c] += kt[c];
    }
    s->stress_t = t;
}

/* K and its integral from stress_t to t (>= stress_t), whatever the flight: for samples
 * and counters, which read the tensor between collisions. */
static inline void stress_kinetic_at(const gr_edmd *s, int dim, double t, double *k_out,
                                     double *int_out)
{
    const double tau = t - s->stress_t;
    if (s->le) {
        stress_le_at(dim, s->cfg.shear_rate, s->st_kin, tau, k_out, int_out);
    } else if (stress_gravity(s)) {
        stress_gravity_at(s, dim, tau, k_out, int_out);
    } else {
        for (int c = 0; c < dim * dim; c++) {
            k_out[c] = s->st_kin[c];
            int_out[c] = s->st_kin[c] * tau;
        }
    }
}

/* Bring the kinetic tensor's integral to time t (>= stress_t). */
static inline void stress_sync(gr_edmd *s, int dim, double t)
{
    if (s->le) {
        stress_le_sync(s, dim, t);
        return;
    }
    if (stress_gravity(s)) {
        stress_gravity_sync(s, dim, t);
        return;
    }
    const double dt = t - s->stress_t;
    for (int k = 0; k < dim * dim; k++) s->st_kin_time[k] += s->st_kin[k] * dt;
    s->stress_t = t;
}

/* The kinetic tensor summed from the velocities (records hold the velocities at each
 * particle's own clock: right for constant velocity, see kinetic_total; a sheared box's
 * peculiar ones, and under gravity the velocities, are taken at stress_t). */
static inline void stress_resum(gr_edmd *s, int dim)
{
    double k[9] = {0.0};
    const int falls = stress_gravity(s);
    for (int32_t i = 0; i < s->n; i++) {
        double V[3] = {0.0, 0.0, 0.0}; /* sheared: peculiar; gravity: v at stress_t */
        const double *p = rec(s, dim, i);
        if (s->le) stress_le_peculiar(s, dim, p, s->stress_t, V);
        if (falls)
            for (int a = 0; a < dim; a++)
                V[a] = fl_vel_at(GR_FLIGHT_GRAVITY, VEL(p, dim)[a], s->cfg.gravity[a],
                                 s->stress_t - TIME(p, dim));
        const double *v = s->le || falls ? V : VEL(p, dim), m = s->mass[i];
        for (int a = 0; a < dim; a++)
            for (int b = 0; b < dim; b++) k[a * dim + b] += m * v[a] * v[b];
    }
    for (int c = 0; c < dim * dim; c++) s->st_kin[c] = k[c];
}

/* One particle's velocity changed from vb to v at t: the kinetic tensor's change. */
static inline void stress_kick(gr_edmd *s, int dim, double m, const double *vb, const double *v)
{
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++) s->st_kin[a * dim + b] += m * (v[a] * v[b] - vb[a] * vb[b]);
}

/* A pair collision at t with separation dr = x_j - x_i: i's velocity went from vib to vi,
 * j's from vjb to vj.  The impulse on j is taken from j's velocity change (whatever the
 * rule: a tangential part makes W asymmetric, as it should). */
static inline void stress_pair(gr_edmd *s, int dim, double t, const double *dr, double mi,
                               const double *vib, const double *vi, double mj,
                               const double *vjb, const double *vj)
{
    stress_sync(s, dim, t);
    for (int a = 0; a < dim; a++)
        for (int b = 0; b < dim; b++) s->st_coll[a * dim + b] += dr[a] * (mj * (vj[b] - vjb[b]));
    stress_kick(s, dim, mi, vib, vi);
    stress_kick(s, dim, mj, vjb, vj);
}

/* A wall collision at t: only the kinetic tensor changes (walls stay out of W). */
static inline void stress_wall(gr_edmd *s, int dim, double t, double m, const double *vb,
                               const double *v)
{
    stress_sync(s, dim, t);
    stress_kick(s, dim, m, vb, v);
}

#endif
