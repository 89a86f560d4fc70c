/* common.h -- status codes and the error record shared by every C file of granular.
 *
 * Every public C function returns an int status: GR_OK (0) on success, a negative
 * GR_ERR_* on failure.  Functions that can fail for a reason worth naming also fill a
 * gr_error so that the binding can build a precise Python exception (which particles,
 * at what time).  Nothing here prints, exits or knows Python. */
#ifndef GR_COMMON_H
#define GR_COMMON_H

#include <stdint.h>

enum {
    GR_OK = 0,
    GR_ERR_NOMEM = -1,     /* an allocation failed */
    GR_ERR_VALUE = -2,     /* an argument is invalid (message in gr_error.what) */
    GR_ERR_OVERLAP = -3,   /* particles i and j overlap */
    GR_ERR_COLLAPSE = -4,  /* inelastic collapse: events pile up at one instant */
    GR_ERR_NONFINITE = -5, /* a NaN or infinity appeared */
    GR_ERR_UNSTABLE = -6,  /* an integrator step is at or past its stability limit */
    GR_ERR_OUTSIDE = -7    /* particle i lies outside the box */
};

typedef struct {
    int code;          /* one of the GR_ERR_* above */
    int64_t i, j;      /* particles involved, -1 if none */
    double t;          /* simulation time, NaN if not applicable */
    double value;      /* a quantity worth reporting (overlap depth, gamma*dt, ...) */
    const char *what;  /* static string describing the problem, or NULL */
} gr_error;

/* For the few helpers whose inlined copies must each see constant arguments (a
 * dimension, a periodic flag) to be compiled apart. */
#if defined(__GNUC__) || defined(__clang__)
#define GR_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define GR_ALWAYS_INLINE inline
#endif

static inline void gr_error_set(gr_error *e, int code, int64_t i, int64_t j, double t,
                                double value, const char *what)
{
    if (!e) return;
    e->code = code; e->i = i; e->j = j; e->t = t; e->value = value; e->what = what;
}

#endif
