/* sde.h -- underdamped Langevin equation and underdamped scaled Brownian motion (UDSBM)
 * for N independent particles: public interface.
 *
 *   dx = v dt,   dv = -gamma(t) v dt + sqrt(2 D(t)) gamma(t) dW
 *   Langevin: gamma = gamma0, D = D0;
 *   UDSBM: gamma0 (1 + t/tau0)^-a, D0 (1 + t/tau0)^-a  (a = exponent: 1 is the thesis'
 *   UDSBM, Haff's cooling; 5/6 the viscoelastic gas' T ~ t^(-5/3))
 *
 * Schemes: Euler-Maruyama exactly as the thesis' (2.92)/(2.110), or the exact update of
 * the Ornstein-Uhlenbeck process over a step (coefficients frozen at the step's midpoint
 * for UDSBM: exact for the OU step, O((dt/tau0)^2) per step for the time dependence).
 * External forces (Langevin model only): per axis a uniform acceleration g_a and a harmonic
 * trap of stiffness per unit mass w_a = k_a/m >= 0 about a centre, so that
 *   dv_a = [g_a - w_a (X_a - c_a) - gamma0 v_a] dt + sqrt(2 D0) gamma0 dW_a.
 * The drift is linear in (X, v): the exact scheme stays exact (the step of a linear SDE is
 * Gaussian with a closed-form mean and covariance, see sde.c); Euler-Maruyama takes the
 * force at the start of the step.
 * Random numbers come from rng.h, keyed by (step, particle): results do not depend on
 * chunking or threads.  The caller owns the inputs, outputs and the carried scratch; a
 * call allocates only its threads' scratch and the block sums (freed before it returns). */
#ifndef GR_SDE_H
#define GR_SDE_H

#include <stdint.h>

#include "common.h"
#include "tamsd.h"

enum { GR_SDE_LANGEVIN = 0, GR_SDE_UDSBM = 1 };
enum { GR_SDE_EM = 0, GR_SDE_EXACT = 1 };

typedef struct {
    int dim;                 /* 1, 2 or 3 */
    int model, scheme;
    double gamma0, D0, tau0; /* tau0 = +inf for Langevin */
    double exponent;         /* a of UDSBM's (1 + t/tau0)^-a, > 0; 1 takes the thesis'
                                1/(1 + t/tau0) exactly as before (no pow) */
    double dt;
    uint64_t key;            /* random stream key */
    /* External forces; force = 0 (all the rest unread) is the force-free run, its bits and
     * cost those of a build without forces. */
    int force;
    double accel[3];         /* g_a: uniform acceleration (force per mass), finite */
    double stiffness[3];     /* w_a = k_a / m >= 0, finite: the trap's force per mass and
                                length (0: no trap along a) */
    const double *origin;    /* count x dim: each particle's start X - c relative to the
                                trap's centre (the state x is the displacement from the
                                start), or NULL for all at the centre */
} gr_sde_config;

/* Largest step count of a run: step counters plus a lag's stride then stay far from
 * INT64_MAX (a stride is at most lag/4 and lags beyond the run are never reached). */
#define GR_SDE_MAX_STEPS ((int64_t)1 << 62)

/* Particles per block of the ensemble sums: x2 and v2 are sums, in block order, of each
 * block's sum over its particles in index order -- an order fixed by the particles'
 * indices alone, so the bits are the same however the particles are split into calls and
 * threads. */
#define GR_SDE_BLOCK 32

/* What a run accumulates.  Sample k is taken after step sample_steps[k] (0 = the start);
 * lags are in steps. */
typedef struct {
    int64_t n_samples;
    const int64_t *sample_steps; /* increasing, >= 0 */
    double *x2;                  /* n_samples x dim: sum over particles of x_a^2 */
    double *v2;                  /* n_samples x dim: sum over particles of v_a^2 */
    double *positions;           /* n_samples x n x dim, or NULL */
    int64_t n_lags;
    const int64_t *lags;         /* increasing, >= 1 */
    int estimator;               /* GR_TAMSD_STRIDED or GR_TAMSD_ALL (tamsd.h) */
    double *tamsd;               /* n x n_lags: per particle, sum over windows of |dx|^2 */
    double *ring;                /* gr_tamsd_ring_size doubles: one particle's stored window
                                    starts.  Scratch for a whole run; carried from call to
                                    call when a run is split into step segments */
    double *carry;               /* 2 x n_samples x dim (x2's then v2's), or NULL: the sums
                                    of a block a call leaves open (its last particles, or
                                    the rest of its particle's steps, come in a later call);
                                    zero at the start of a run.  NULL: the call ends the
                                    sums (its last block is added to x2, v2) */
    double *step_coef;           /* optional scratch, 5 x (step_to - step_from): the exact
                                    scheme's UDSBM coefficients per step (Euler-Maruyama's,
                                    2 a step, for an exponent != 1), computed once per
                                    call instead of once per particle and step; NULL
                                    computes them inline (the same numbers) */
} gr_sde_output;

/* Advance particles [first, first + count) of n over the steps [step_from, step_to) of a
 * run of n_steps <= GR_SDE_MAX_STEPS steps: positions x and velocities v (count x dim)
 * hold the state at step_from in (x = 0 at the particle's origin at step 0) and at
 * step_to out.  Samples and TAMSD windows are booked at the steps step_from .. step_to-1,
 * and at n_steps when step_to = n_steps, so a run is one call over [0, n_steps] or calls
 * over consecutive segments [s0 = 0, s1), [s1, s2), ..., ending at n_steps, with the same
 * results to the bit.  A segment that is not the whole run takes one particle (count <= 1)
 * and the ring its previous segment left.  The particles are split into `threads` (>= 1)
 * POSIX threads by whole blocks; the results are the same to the bit for any count.
 * Returns GR_OK, GR_ERR_VALUE (also: a force with UDSBM, a non-finite force, a negative
 * stiffness), GR_ERR_NOMEM, GR_ERR_NONFINITE or GR_ERR_UNSTABLE (Euler-Maruyama with
 * gamma0 dt >= 2, or in a trap with w_a dt >= gamma0: sde.c). */
int gr_sde_run(const gr_sde_config *cfg, int64_t n, int64_t first, int64_t count,
               int64_t step_from, int64_t step_to, int64_t n_steps, double *x, double *v,
               gr_sde_output *out, int threads, gr_error *err);

/* The exact scheme's coefficients of one axis under a force (sde.c's force_exact_for):
 * out = (e12, e22, j1, kx, sx, sv) for friction gamma, diffusivity D, stiffness per mass
 * w >= 0 and step dt -- for the tests, which compare them with slower methods. */
void gr_sde_force_step(double gamma, double D, double w, double dt, double out[6]);

#endif
