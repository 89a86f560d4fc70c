/* drive.h -- the random driving force of a granular gas ("white-noise thermostat",
 * Williams & MacKintosh 1996, Phys. Rev. E 54, R9; van Noije & Ernst 1998, Granular
 * Matter 1, 57): random velocity kicks at random times, exactly, in the event loop.
 *
 * The process.  Kicks happen at the times of a Poisson process of total rate
 * Gamma = drive_rate * N / 2 (so each particle is kicked drive_rate times per unit time on
 * average); kick k picks a pair (i, j), i != j, uniformly among the N (N - 1) ordered pairs
 * and changes the two velocities with equal and opposite momenta, so the total momentum is
 * kept exactly (up to rounding):
 *  - GR_DRIVE_WHITE_NOISE: dp = 2 mu s z, z a standard normal d-vector, mu the pair's
 *    reduced mass, s^2 = drive_strength / drive_rate; v_i += dp / m_i, v_j -= dp / m_j.
 *    Equal masses: each velocity changes by +-s z.  A particle's velocity then diffuses
 *    with <dv_a dv_b> = xi0^2 dt delta_ab, xi0^2 = drive_strength: van Noije & Ernst's
 *    white noise (their eq. 2.2 with xi0^2), heating each particle by d m xi0^2 / 2 per
 *    unit time on average (dT/dt = m xi0^2, T = m <v^2> / d).  It is white noise in the
 *    limit of small kicks, s^2 << T/m: the next order of the Kramers-Moyal expansion adds
 *    to d<v^4>/dt a fraction s^2 m / (2 T) of the diffusion's part (a term of order
 *    m xi0^2 / (2 T drive_rate)).  The pair's opposite kicks make two velocities
 *    correlated, a correlation of order 1/N between any two particles (the centre of mass
 *    does not move).
 *  - GR_DRIVE_THERMOSTAT: the pair's relative velocity is drawn anew from the Maxwellian
 *    at temperature T = drive_strength (each component sqrt(T / mu) z), its centre-of-mass
 *    velocity kept: a momentum-conserving Andersen-like thermostat (a pair form of Lowe's
 *    1999 scheme, all components), which leaves the canonical distribution of an elastic
 *    gas at T (with fixed total momentum) unchanged.
 *
 * Exactly in EDMD: a kick is an event at its own time, not a step.  The plain loop runs
 * up to the next kick's time (gr_edmd_advance_plain with that stop), the two particles are
 * moved to it, kicked, and predicted anew; their collision counters go up so that every
 * prediction made with their old velocities is found stale (edmd.c's lazy invalidation).
 * So scenes without driving run the same loop as before, instruction for instruction.
 *
 * Random numbers: counter-based (rng.h), keyed by drive_seed: kick k draws its pair and
 * its normals from stream (seed, k, 0), and the waiting time before it from stream
 * (seed, k, 1) as -log(U) / Gamma.  The state is only (the time of the next kick, the
 * number of kicks done), saved in checkpoints: a run continues bit for bit however it
 * is chunked. */
#ifndef GR_DRIVE_H
#define GR_DRIVE_H

#include <stdint.h>

#include "edmd.h"

#define GR_DRIVE_NONE 0
#define GR_DRIVE_WHITE_NOISE 1
#define GR_DRIVE_THERMOSTAT 2
/* seeds are integers below 2^53, which a double holds exactly */
#define GR_DRIVE_SEED_LIMIT 9007199254740992.0

/* gr_edmd_advance for a driven system (same contract). */
int gr_drive_advance(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err);

/* The waiting time before kick k (k = 0: from time 0). */
double gr_drive_wait(const gr_edmd_config *cfg, int64_t k);

/* The driving's part of a configuration's checks (validate.c): GR_OK or GR_ERR_VALUE. */
int gr_drive_check(const gr_edmd_config *cfg, gr_error *err);

#endif
