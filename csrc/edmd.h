/* edmd.h -- the event-driven molecular dynamics engine for hard disks (2D) and hard
 * spheres (3D): public interface.
 *
 * A gr_edmd holds one system: particle states with their own clocks, the cell grid, the
 * event queue and the counters.  gr_edmd_advance() processes events until a stop
 * criterion or the caller's event budget is met, writing samples into caller-owned
 * buffers on the way; a run can be continued by calling it again.  Nothing here
 * allocates output for the caller, prints or exits.
 *
 * Status codes (common.h): GR_OK or a GR_STOP_* reason (positive) on success, GR_ERR_*
 * (negative) on failure, with a gr_error filled in.
 *
 * The engine's files: edmd.c the event loop, the events and the predictions (read it
 * first), search.h their pair searches; engine.h the system's struct; schedstate.h a particle's scheduling state;
 * cells.c/.h the cell grid; nlist.c/.h the neighbour lists; big.c/.h big particles;
 * calendar.c/.h the queue; collide.h two-body geometry; flight.h the motion between
 * events, boundary.h the box's faces and images, rule.h the collision rules (the three
 * seams a new dynamics, boundary or rule changes); build.c construction;
 * validate.c the checks of a configuration; renumber.c renumbering in cell order;
 * sample.c samples, state and counters. */
#ifndef GR_EDMD_H
#define GR_EDMD_H

#include <stddef.h>
#include <stdint.h>

#include "common.h"
#include "restitution.h"

/* Why gr_edmd_advance returned (all are successes). */
enum {
    GR_STOP_TIME = 1,       /* reached stop->t_stop */
    GR_STOP_BUDGET = 2,     /* processed stop->max_events events; call again to go on */
    GR_STOP_COLLISIONS = 3, /* mean collisions per particle reached the target */
    GR_STOP_ENERGY = 4,     /* mean kinetic energy fell to the target */
    GR_STOP_IDLE = 5        /* no event will ever happen again and t_stop is infinite */
};

/* A vibrating wall (vibwall.h): the face of `axis` on `side` (0 at lo, 1 at hi) moves as
 * c + amplitude * f(omega t + phase), f = sin or the triangle wave.  Zeroed: none. */
enum { GR_WAVE_SINE = 0, GR_WAVE_TRIANGLE = 1 };
typedef struct {
    int on;                   /* 1: a vibrating wall; 0: none (the rest unused) */
    int axis;                 /* 0 .. dim-1 */
    int side;                 /* 0: the face at lo, 1: at hi */
    int waveform;             /* GR_WAVE_SINE or GR_WAVE_TRIANGLE */
    double amplitude;         /* A > 0 (length) */
    double omega;             /* angular frequency > 0 (1 / time) */
    double phase;             /* radians, finite */
} gr_vibwall;

/* The largest |g| times the box's longest side (validate.c): a speed squared, within the
 * square of the scale limit 1e140 (granular/_scales.py). */
#define GR_GRAVITY_GL_MAX 1e280

typedef struct {
    int dim;                  /* 2 or 3 */
    int64_t n;                /* number of particles, >= 1 */
    double lo[3], hi[3];      /* box corners, per axis (only the first dim used) */
    int periodic;             /* 1: periodic on every axis; 0: reflecting walls */
    double wall_restitution;  /* walls: v' = e_w * (v reflected) (thesis 2.22); > 0 */
    double restitution;       /* xi in [0, 1] for pair collisions */
    double contact_duration;  /* TC model t_c >= 0; 0 turns it off */
    double cell_factor;       /* cell width / largest diameter in the grid, >= 1 (speed knob) */
    double big_ratio;         /* particles more than this times the median diameter wide
                               * (at most GR_BIG_MAX of them) stay out of the cell grid
                               * (>= 1; +inf: none) -- a speed knob, see big.h */
    double shell;             /* > 0: neighbour lists with a shell this many largest
                               * diameters thick (no big particles then); 0: cell
                               * crossings -- a speed knob, see nlist.h */
    double shear_rate;        /* periodic only: Lees-Edwards images across the y faces
                               * sliding along x at shear_rate * L_y (boundary.h); 0: none */
    double shear_offset;      /* their x offset at time 0, in [0, L_x) */
    double gravity[3];        /* uniform acceleration on every particle (only the first dim
                               * used; all 0: constant velocity, flight.h) */
    int free_fall;            /* 1: gravity in a periodic box allowed (the centre of mass
                               * falls forever); 0: refused there */
    gr_law law, wall_law;     /* kind GR_LAW_CONSTANT (zeroed): restitution and
                               * wall_restitution above; else eps(v_n) replaces them
                               * (restitution.h).  gr_edmd_new copies the tables. */
    int stress;               /* 1: keep the stress tensor's accumulators (stress.h) */
    /* The random driving force (drive.h): kicks to random pairs at the times of a Poisson
     * process.  drive_kind GR_DRIVE_NONE (0) turns it off, and the others are then unused;
     * drive_rate: kicks each particle receives per unit time on average (> 0); drive_strength:
     * the white noise's xi0^2 (GR_DRIVE_WHITE_NOISE) or the thermostat's temperature
     * (GR_DRIVE_THERMOSTAT); drive_seed: the random numbers' key, an integer in [0, 2^53). */
    double drive_kind, drive_rate, drive_strength, drive_seed;
    double tangential_restitution; /* rough particles (rule.h): beta in [-1, 1], -1 smooth;
                                    * beta_0 of the Coulomb rule */
    double inertia_factor;    /* rough particles: I = q m r^2, q in (0, 1] */
    double friction;          /* rough particles: Coulomb's mu >= 0 (Walton's rule); +inf:
                               * constant beta */
    const double *spin;       /* NULL: smooth particles.  Else their angular velocities
                               * (n in 2D, n x 3 in 3D), and the rough rule; gr_edmd_new
                               * copies them */
    gr_vibwall vib;           /* a vibrating wall (walls only); vib.on 0: none */
} gr_edmd_config;

typedef struct {
    double t_stop;                 /* absolute time; +inf for none */
    double collisions_per_particle;/* stop when (2*pair + wall)/N >= this; +inf for none */
    int energy;                    /* 1: stop when the mean kinetic energy <= kinetic_energy
                                    * (> 0); 0: no energy criterion */
    double kinetic_energy;
    int64_t max_events;            /* events this call may process (> 0) */
} gr_edmd_stop;

/* Caller-owned sample buffers.  Sample k is the state at times[k]; `next` is the index
 * of the first sample not yet written and is advanced by gr_edmd_advance.  pos/vel may
 * be NULL when the caller wants only the statistics. */
typedef struct {
    int64_t count;
    const double *times;  /* increasing */
    int64_t next;
    double *pos;          /* count x n x dim, unwrapped positions, or NULL */
    double *vel;          /* count x n x dim, or NULL */
    double *kinetic;      /* count: total kinetic energy */
    double *momentum;     /* count x dim: total momentum */
    int64_t *pair;        /* count: cumulative pair collisions */
    int64_t *wall;        /* count: cumulative wall collisions */
    double *virial;       /* count: cumulative pair virial sum over collisions of r_ij . dp_j */
    double *wall_impulse; /* count: cumulative normal momentum given to the walls */
    /* with cfg.stress (else ignored), count x dim x dim each: */
    double *stress_collisional; /* cumulative sum over pair collisions of r_a dp_b */
    double *kinetic_time_tensor;/* cumulative integral of sum m v_a v_b over time */
    double *kinetic_tensor;     /* sum m v_a v_b at the sample */
    double *spin;         /* count x n x (1 in 2D, 3 in 3D): angular velocities, or NULL
                           * (always NULL for smooth particles) */
    /* a vibrating wall (vibwall.h), count each, or NULL: cumulative, as the counters' */
    double *wall_work;      /* the work it did on the particles */
    double *collision_loss; /* the kinetic energy pair and wall collisions dissipated */
} gr_edmd_samples;

typedef struct {
    double t;               /* current time of the system */
    int64_t events;         /* all events processed, crossings and exits included */
    int64_t pair;           /* pair collisions */
    int64_t wall;           /* wall collisions */
    int64_t crossings;      /* cell crossings (none with neighbour lists) */
    int64_t shell_exits;    /* neighbour lists: shell exits, each rebuilding one list */
    int64_t invalid;        /* events found stale on pop (partner collided since) */
    int64_t elastic_tc;     /* pair collisions made elastic by the TC model */
    int64_t law_clamped;    /* collisions faster than a viscoelastic law's range */
    double virial;          /* sum over pair collisions of r_ij . dp_j */
    double wall_impulse;    /* sum over wall collisions of |dp_normal| */
    double kinetic;         /* total kinetic energy now */
    double kinetic_time;    /* integral over time of the total kinetic energy */
    double shear_work;      /* Lees-Edwards: work of the sliding images, the x momentum
                             * carried across the y faces times the velocity jump u */
    double wall_work;       /* vibrating wall: sum over its hits of J U (J the normal impulse
                             * it gives, U its velocity then): the work it did */
    double collision_loss;  /* vibrating wall: the kinetic energy lost in pair and wall
                             * collisions (pairs: the energy before less after; walls:
                             * m (1 - e^2) w^2 / 2, w the speed relative to the wall) */
    int ncell[3];           /* cells per axis */
    double shell;           /* the neighbour lists' shell in largest diameters, 0: none
                             * (a box too small for the shell asked for has none) */
    /* with cfg.stress (else zeros), dim x dim row-major: */
    double stress_collisional[9];  /* sum over pair collisions of r_a dp_b */
    double kinetic_time_tensor[9]; /* integral over time of sum m v_a v_b */
    double kinetic_tensor[9];      /* sum m v_a v_b now */
    int64_t kicks;          /* random driving: kicks done (each to one pair) */
    double drive_energy;    /* random driving: kinetic energy the kicks gave, summed */
} gr_edmd_counters;

typedef struct gr_edmd gr_edmd;

/* Build a system from arrays (pos, vel: n x dim; radius, mass: n).  The arrays are
 * copied.  Checks that particles lie in the box, do not overlap, and that a periodic
 * box is more than two largest diameters wide.  Returns GR_OK, GR_ERR_VALUE,
 * GR_ERR_OUTSIDE, GR_ERR_OVERLAP, GR_ERR_NONFINITE or GR_ERR_NOMEM. */
int gr_edmd_new(gr_edmd **out, const gr_edmd_config *cfg, const double *pos,
                const double *vel, const double *radius, const double *mass, gr_error *err);
void gr_edmd_free(gr_edmd *s);

/* The checks of gr_edmd_new without building a system: arguments, finiteness, the box,
 * overlaps (through a cell grid, O(N)).  Same status codes. */
int gr_edmd_check(const gr_edmd_config *cfg, const double *pos, const double *vel,
                  const double *radius, const double *mass, gr_error *err);

/* What the engine allocates per particle, in bytes, with and without neighbour lists
 * (at the lists' starting capacity), for estimates of memory before a run. */
size_t gr_edmd_bytes_per_particle(int dim, int lists);

/* Process events.  Returns a GR_STOP_* reason, or GR_ERR_COLLAPSE / GR_ERR_NONFINITE
 * (the state stays consistent and inspectable after an error), or GR_ERR_NOMEM (a
 * neighbour list could not grow: the state can be inspected, but every further call
 * returns GR_ERR_NOMEM). */
int gr_edmd_advance(gr_edmd *s, const gr_edmd_stop *stop, gr_edmd_samples *smp, gr_error *err);

/* Choose the compilation of the neighbour-list scan this CPU runs (call once, before the
 * first run); gr_scan_kernel names it: "avx2" or "plain". */
void gr_scan_init(void);
const char *gr_scan_kernel(void);

/* The state at the current time: positions wrapped into the box (pos), velocities, and
 * image counters (unwrapped = pos + image * box length).  Any pointer may be NULL.
 * Does not change the system. */
void gr_edmd_state(const gr_edmd *s, double *pos, double *vel, int64_t *image);
void gr_edmd_get_counters(const gr_edmd *s, gr_edmd_counters *c);
/* Rough particles: whether s carries spins, and their angular velocities now (n in 2D,
 * n x 3 in 3D, in the caller's order; they do not change in flight). */
int gr_edmd_has_spin(const gr_edmd *s);
void gr_edmd_spin(const gr_edmd *s, double *spin);

#endif
