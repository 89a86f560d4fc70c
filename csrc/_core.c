/* _core.c -- the one binding between Python and the C core of granular.
 *
 * This is the only file that includes Python.h.  It checks arguments (shapes, dtypes,
 * contiguity), allocates every output as a fresh NumPy array, releases the GIL while C
 * runs, and turns the core's status codes into the exceptions of granular.errors.  No
 * physics lives here. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <numpy/arrayobject.h>
#include <math.h>
#include <string.h>

#include "big.h"
#include "cells.h"
#include "checkpoint.h"
#include "common.h"
#include "drive.h"
#include "edmd.h"
#include "rng.h"
#include "scene_params.h"
#include "sde.h"

/* ------------------------------------------------------------------------------------ */
/* Errors                                                                                 */
/* ------------------------------------------------------------------------------------ */

static PyObject *errors_module; /* granular.errors, imported once at module init */

/* Raise the granular.errors class that matches a core status, with a message naming
 * what went wrong.  Always returns NULL so callers can `return raise_status(...)`. */
static PyObject *raise_status(int status, const gr_error *e)
{
    const char *cls = "GranularError";
    char msg[512];
    const char *what = (e && e->what) ? e->what : "";
    int64_t i = e ? e->i : -1, j = e ? e->j : -1;
    double t = e ? e->t : NAN, value = e ? e->value : NAN;

    switch (status) {
    case GR_ERR_NOMEM:
        if (!what[0]) return PyErr_NoMemory();
        PyErr_SetString(PyExc_MemoryError, what);
        return NULL;
    case GR_ERR_VALUE:
        PyErr_SetString(PyExc_ValueError, what[0] ? what : "invalid argument");
        return NULL;
    case GR_ERR_OVERLAP:
        cls = "OverlapError";
        snprintf(msg, sizeof msg, "particles %lld and %lld overlap by %.6g%s%s",
                 (long long)i, (long long)j, value, what[0] ? ": " : "", what);
        break;
    case GR_ERR_OUTSIDE:
        cls = "OutsideBoxError";
        snprintf(msg, sizeof msg, "particle %lld lies outside the box%s%s", (long long)i,
                 what[0] ? ": " : "", what);
        break;
    case GR_ERR_COLLAPSE:
        cls = "InelasticCollapseError";
        if (j >= 0)
            snprintf(msg, sizeof msg,
                     "inelastic collapse at t = %.17g: particles %lld and %lld collide over and "
                     "over at one instant (%s); set contact_duration > 0 to use the TC model",
                     t, (long long)i, (long long)j, what[0] ? what : "events pile up");
        else
            snprintf(msg, sizeof msg,
                     "inelastic collapse at t = %.17g: particle %lld has event after event (with "
                     "walls, or crossing cells) at one instant (%s); set contact_duration > 0 "
                     "to use the TC model",
                     t, (long long)i, what[0] ? what : "events pile up");
        break;
    case GR_ERR_NONFINITE:
        cls = "NonFiniteError";
        snprintf(msg, sizeof msg, "a non-finite number appeared%s%s (particle %lld, t = %g)",
                 what[0] ? ": " : "", what, (long long)i, t);
        break;
    case GR_ERR_UNSTABLE:
        cls = "UnstableStepError";
        snprintf(msg, sizeof msg, "%s", what[0] ? what : "step size at or past the stability limit");
        break;
    default:
        snprintf(msg, sizeof msg, "C core failed with status %d%s%s", status,
                 what[0] ? ": " : "", what);
    }

    PyObject *type = PyObject_GetAttrString(errors_module, cls);
    if (!type) return NULL;
    PyObject *args = Py_BuildValue("(s)", msg);
    PyObject *kw = NULL, *exc = NULL;
    if (args) {
        PyObject *parts = (j >= 0) ? Py_BuildValue("(LL)", (long long)i, (long long)j)
                        : (i >= 0) ? Py_BuildValue("(L)", (long long)i)
                                   : PyTuple_New(0);
        if (parts) {
            kw = Py_BuildValue("{s:N,s:d,s:d}", "particles", parts, "time", t, "value", value);
            if (kw) exc = PyObject_Call(type, args, kw);
        }
    }
    if (exc) PyErr_SetObject(type, exc);
    Py_XDECREF(exc);
    Py_XDECREF(kw);
    Py_XDECREF(args);
    Py_DECREF(type);
    return NULL;
}

/* A C-contiguous float64 array of the given shape (ndim entries; -1 = any), or NULL with
 * a ValueError naming the argument. */
static PyArrayObject *as_f64(PyObject *obj, const char *name, int ndim, const npy_intp *shape)
{
    PyArrayObject *a = (PyArrayObject *)PyArray_FROMANY(obj, NPY_FLOAT64, ndim, ndim,
                                                        NPY_ARRAY_IN_ARRAY);
    if (!a) {
        PyErr_Format(PyExc_ValueError, "%s must be a %d-dimensional array of float64", name, ndim);
        return NULL;
    }
    for (int k = 0; k < ndim; k++) {
        if (shape[k] >= 0 && PyArray_DIM(a, k) != shape[k]) {
            PyErr_Format(PyExc_ValueError, "%s has length %zd along axis %d, expected %zd",
                         name, (Py_ssize_t)PyArray_DIM(a, k), k, (Py_ssize_t)shape[k]);
            Py_DECREF(a);
            return NULL;
        }
    }
    return a;
}

/* a * b for sizes (>= 0), or 0 with an OverflowError naming the buffer when the product
 * does not fit npy_intp: a size check must not wrap round and pass a short buffer. */
static int mul_size(npy_intp a, npy_intp b, npy_intp *out, const char *name)
{
    if (a < 0 || b < 0 || (b != 0 && a > NPY_MAX_INTP / b)) {
        PyErr_Format(PyExc_OverflowError, "the size of %s, %zd x %zd elements, overflows",
                     name, (Py_ssize_t)a, (Py_ssize_t)b);
        return 0;
    }
    *out = a * b;
    return 1;
}

/* ==== EDMD binding begin ============================================================ */

typedef struct {
    PyObject_HEAD
    gr_edmd *sim;
    int dim;
    npy_intp n;
    int busy; /* a thread is inside advance() with the GIL released */
} EDMDObject;

static void EDMD_dealloc(EDMDObject *self)
{
    gr_edmd_free(self->sim);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

/* Every argument of the engine's entry points is a keyword ("|$" in the format): a wrong
 * name is a TypeError and two numbers cannot swap places.  PyArg_ParseTupleAndKeywords
 * cannot make a keyword-only argument required, so the first `required` of names[] are
 * checked here, after it (which names an unknown keyword).  Returns 0, or -1 with a
 * TypeError set. */
static int require_keywords(PyObject *args, PyObject *kw, char **names, int required,
                            const char *function)
{
    if (args && PyTuple_GET_SIZE(args) > 0) {
        PyErr_Format(PyExc_TypeError,
                     "%s() takes no positional arguments (%zd given): give each by name",
                     function, PyTuple_GET_SIZE(args));
        return -1;
    }
    for (int i = 0; i < required; i++) {
        PyObject *value = kw ? PyDict_GetItemString(kw, names[i]) : NULL;
        if (!value) {
            PyErr_Format(PyExc_TypeError, "%s() missing required keyword argument '%s'",
                         function, names[i]);
            return -1;
        }
    }
    return 0;
}

/* A restitution law from None (constant: *law zeroed) or a dict {kind, scale, v_max,
 * speeds, values} as granular/restitution.py builds it (RestitutionLaw._engine); the table
 * arrays are returned in *x, *y (new references, or NULL) and must outlive the use of
 * *law.  Returns 0, or -1 with an exception set.  The engine checks the values
 * (validate.c). */
static int parse_law(PyObject *obj, const char *name, gr_law *law, PyArrayObject **x,
                     PyArrayObject **y)
{
    static char *names[] = {"kind", "scale", "v_max", "speeds", "values", NULL};
    memset(law, 0, sizeof *law);
    *x = *y = NULL;
    if (obj == Py_None) return 0;
    if (!PyDict_Check(obj)) {
        PyErr_Format(PyExc_TypeError,
                     "%s must be None or a dict of kind, scale, v_max, speeds and values", name);
        return -1;
    }
    char format[64];
    snprintf(format, sizeof format, "|$iddOO:%s", name);
    PyObject *ox, *oy, *none = PyTuple_New(0);
    if (!none) return -1;
    int ok = PyArg_ParseTupleAndKeywords(none, obj, format, names, &law->kind, &law->scale,
                                         &law->v_max, &ox, &oy) &&
             require_keywords(NULL, obj, names, 5, name) == 0;
    Py_DECREF(none);
    if (!ok) return -1;
    npy_intp any[1] = {-1};
    if (!(*x = as_f64(ox, "a law's speeds", 1, any))) return -1;
    npy_intp shape[1] = {PyArray_DIM(*x, 0)};
    if (!(*y = as_f64(oy, "a law's values", 1, shape))) {
        Py_CLEAR(*x);
        return -1;
    }
    law->count = (int64_t)shape[0];
    law->speeds = shape[0] ? PyArray_DATA(*x) : NULL;
    law->values = shape[0] ? PyArray_DATA(*y) : NULL;
    return 0;
}

/* A vibrating wall from None (none: *w zeroed) or a dict {axis, side, waveform, amplitude,
 * omega, phase} as granular/walls.py builds it (VibratingWall._engine).  Returns 0, or -1
 * with an exception set.  The engine checks the values (validate.c). */
static int parse_vibwall(PyObject *obj, gr_vibwall *w)
{
    static char *names[] = {"axis", "side", "waveform", "amplitude", "omega", "phase", NULL};
    memset(w, 0, sizeof *w);
    if (obj == Py_None) return 0;
    if (!PyDict_Check(obj)) {
        PyErr_SetString(PyExc_TypeError, "vibrating_wall must be None or a dict of axis, side, "
                                         "waveform, amplitude, omega and phase");
        return -1;
    }
    PyObject *none = PyTuple_New(0);
    if (!none) return -1;
    int ok = PyArg_ParseTupleAndKeywords(none, obj, "|$iiiddd:vibrating_wall", names, &w->axis,
                                         &w->side, &w->waveform, &w->amplitude, &w->omega,
                                         &w->phase) &&
             require_keywords(NULL, obj, names, 6, "vibrating_wall") == 0;
    Py_DECREF(none);
    if (!ok) return -1;
    w->on = 1;
    return 0;
}

/* Parse EDMD's arguments and build a system into *sim, or with sim == NULL only check
 * them (gr_edmd_check: the same checks without building).  Returns 0, or -1 with an
 * exception set. */
/* EDMD's keywords: the particles' arrays, the box, the boundary, the scene's numbers
 * (scene_params.h, in its order), the engine knobs and the laws.  The first
 * EDMD_REQUIRED are required.  _core.EDMD_KEYWORDS is this list. */
#define NAME_OF(field) #field,
#define FORMAT_OF(field) "d"
#define COUNT_OF(field) +1
static char *edmd_names[] = {"positions", "velocities", "radii", "masses", "lower", "upper",
                             "periodic", GR_SCENE_DOUBLES(NAME_OF) "cell_factor", "big_ratio",
                             "shell", "law", "wall_law", "stress", "angular_velocities",
                             "vibrating_wall", "gravity", "free_fall", NULL};
#define EDMD_REQUIRED (7 GR_SCENE_DOUBLES(COUNT_OF))
#define EDMD_FORMAT "|$OOOOOOp" GR_SCENE_DOUBLES(FORMAT_OF) "dddOOpOOOp"

/* Parse EDMD's arguments and build a system into *sim, or with sim == NULL only check
 * them (gr_edmd_check: the same checks without building).  Returns 0, or -1 with an
 * exception set. */
static int edmd_from_args(PyObject *args, PyObject *kw, gr_edmd **sim, int *dim_out,
                          npy_intp *n_out)
{
    PyObject *opos, *ovel, *orad, *omass, *olo, *ohi, *olaw = Py_None, *owall = Py_None;
    PyObject *ospin = Py_None; /* rough particles' angular velocities, or None: smooth */
    PyObject *ovib = Py_None;
    PyObject *ograv = Py_None;
    gr_edmd_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.cell_factor = 1.0;
    cfg.big_ratio = GR_BIG_RATIO;
    cfg.shell = 0.0;
#define ADDRESS_OF(field) &cfg.field,
    if (!PyArg_ParseTupleAndKeywords(args, kw,
                                     sim ? EDMD_FORMAT ":EDMD" : EDMD_FORMAT ":edmd_check",
                                     edmd_names, &opos, &ovel, &orad, &omass, &olo, &ohi,
                                     &cfg.periodic, GR_SCENE_DOUBLES(ADDRESS_OF) &cfg.cell_factor,
                                     &cfg.big_ratio, &cfg.shell, &olaw, &owall, &cfg.stress,
                                     &ospin, &ovib, &ograv, &cfg.free_fall) ||
        require_keywords(args, kw, edmd_names, EDMD_REQUIRED, sim ? "EDMD" : "edmd_check") < 0)
        return -1;
#undef ADDRESS_OF
    if (parse_vibwall(ovib, &cfg.vib) < 0) return -1;
    gr_law law, wall_law;
    PyArrayObject *law_x = NULL, *law_y = NULL, *wall_x = NULL, *wall_y = NULL;
    if (parse_law(olaw, "law", &law, &law_x, &law_y) < 0) return -1;
    if (parse_law(owall, "wall_law", &wall_law, &wall_x, &wall_y) < 0) {
        Py_XDECREF(law_x);
        Py_XDECREF(law_y);
        return -1;
    }
    npy_intp any2[2] = {-1, -1};
    PyArrayObject *pos = as_f64(opos, "positions", 2, any2);
    npy_intp n = pos ? PyArray_DIM(pos, 0) : 0, d = pos ? PyArray_DIM(pos, 1) : 0;
    npy_intp shp[2] = {n, d}, shn[1] = {n}, shd[1] = {d};
    PyArrayObject *vel = NULL, *rad = NULL, *mass = NULL, *lo = NULL, *hi = NULL, *spin = NULL,
                  *grav = NULL;
    npy_intp shw[2] = {n, 3};
    int ok = 0;
    if (!pos) goto done;
    if (d != 2 && d != 3) {
        PyErr_Format(PyExc_ValueError, "positions must have shape (N, 2) or (N, 3), got (N, %zd)",
                     (Py_ssize_t)d);
        goto done;
    }
    if (!(vel = as_f64(ovel, "velocities", 2, shp)) || !(rad = as_f64(orad, "radii", 1, shn)) ||
        !(mass = as_f64(omass, "masses", 1, shn)) || !(lo = as_f64(olo, "lower", 1, shd)) ||
        !(hi = as_f64(ohi, "upper", 1, shd)))
        goto done;
    /* spins: (N,) in 2D (along z), (N, 3) in 3D */
    if (ospin != Py_None && !(spin = as_f64(ospin, "angular_velocities", d == 2 ? 1 : 2, shw)))
        goto done;
    cfg.spin = spin ? PyArray_DATA(spin) : NULL;
    /* gravity: None (none, constant velocity) or d components */
    if (ograv != Py_None) {
        if (!(grav = as_f64(ograv, "gravity", 1, shd))) goto done;
        for (int a = 0; a < d; a++) cfg.gravity[a] = ((double *)PyArray_DATA(grav))[a];
    }
    cfg.dim = (int)d;
    cfg.n = n;
    for (int a = 0; a < d; a++) {
        cfg.lo[a] = ((double *)PyArray_DATA(lo))[a];
        cfg.hi[a] = ((double *)PyArray_DATA(hi))[a];
    }
    cfg.law = law;
    cfg.wall_law = wall_law;
    gr_error err = {0, -1, -1, NAN, NAN, NULL};
    int status;
    Py_BEGIN_ALLOW_THREADS
    if (sim)
        status = gr_edmd_new(sim, &cfg, PyArray_DATA(pos), PyArray_DATA(vel),
                             PyArray_DATA(rad), PyArray_DATA(mass), &err);
    else
        status = gr_edmd_check(&cfg, PyArray_DATA(pos), PyArray_DATA(vel), PyArray_DATA(rad),
                               PyArray_DATA(mass), &err);
    Py_END_ALLOW_THREADS
    if (status != GR_OK) {
        raise_status(status, &err);
        goto done;
    }
    if (dim_out) *dim_out = (int)d;
    if (n_out) *n_out = n;
    ok = 1;
done:
    Py_XDECREF(pos);
    Py_XDECREF(vel);
    Py_XDECREF(rad);
    Py_XDECREF(mass);
    Py_XDECREF(lo);
    Py_XDECREF(hi);
    Py_XDECREF(spin);
    Py_XDECREF(grav);
    Py_XDECREF(law_x);
    Py_XDECREF(law_y);
    Py_XDECREF(wall_x);
    Py_XDECREF(wall_y);
    return ok ? 0 : -1;
}

static int EDMD_init(EDMDObject *self, PyObject *args, PyObject *kw)
{
    if (self->sim) {
        PyErr_SetString(PyExc_RuntimeError, "EDMD is already initialised");
        return -1;
    }
    return edmd_from_args(args, kw, &self->sim, &self->dim, &self->n);
}

static PyObject *edmd_check(PyObject *mod, PyObject *args, PyObject *kw)
{
    if (edmd_from_args(args, kw, NULL, NULL, NULL) < 0) return NULL;
    Py_RETURN_NONE;
}

/* big_cut(radii, big_ratio): the engine's cut, big_ratio times the upper median radius. */
static PyObject *big_cut(PyObject *mod, PyObject *args)
{
    PyObject *orad;
    double ratio;
    if (!PyArg_ParseTuple(args, "Od", &orad, &ratio)) return NULL;
    npy_intp any1[1] = {-1};
    PyArrayObject *rad = as_f64(orad, "radii", 1, any1);
    if (!rad) return NULL;
    const npy_intp n = PyArray_DIM(rad, 0);
    double cut = NAN;
    int status = n < 1 || n > INT32_MAX ? GR_ERR_VALUE
                                        : gr_big_cut(PyArray_DATA(rad), (int32_t)n, ratio, &cut);
    Py_DECREF(rad);
    if (status == GR_ERR_NOMEM) return PyErr_NoMemory();
    if (status != GR_OK) {
        PyErr_SetString(PyExc_ValueError, "radii must hold between 1 and 2^31 - 1 entries");
        return NULL;
    }
    return PyFloat_FromDouble(cut);
}

/* big_particles(radii, lengths, big_ratio, cell_factor): which particles the engine's
 * cell grid keeps out (bool array), by the one rule in big.c. */
static PyObject *big_particles(PyObject *mod, PyObject *args)
{
    PyObject *orad, *olen;
    double ratio, cell_factor;
    if (!PyArg_ParseTuple(args, "OOdd", &orad, &olen, &ratio, &cell_factor)) return NULL;
    npy_intp any1[1] = {-1};
    PyArrayObject *rad = as_f64(orad, "radii", 1, any1), *len = NULL;
    PyObject *out = NULL;
    if (!rad) return NULL;
    const npy_intp n = PyArray_DIM(rad, 0);
    if (!(len = as_f64(olen, "lengths", 1, any1))) goto done;
    const npy_intp d = PyArray_DIM(len, 0);
    if ((d != 2 && d != 3) || n < 1 || n > INT32_MAX) {
        PyErr_SetString(PyExc_ValueError, "lengths must have 2 or 3 entries and radii at least one");
        goto done;
    }
    out = PyArray_ZEROS(1, &n, NPY_BOOL, 0);
    if (!out) goto done;
    double L[3] = {1.0, 1.0, 1.0};
    for (int a = 0; a < d; a++) L[a] = ((double *)PyArray_DATA(len))[a];
    gr_big b = {0};
    b.is_big = PyArray_DATA((PyArrayObject *)out); /* npy_bool is one byte, like uint8_t */
    if (gr_big_choose(&b, (int)d, (int32_t)n, PyArray_DATA(rad), L, ratio, cell_factor) != GR_OK) {
        Py_CLEAR(out);
        PyErr_NoMemory();
    }
done:
    Py_DECREF(rad);
    Py_XDECREF(len);
    return out;
}

static PyObject *edmd_bytes_per_particle(PyObject *mod, PyObject *args)
{
    int dim, lists;
    if (!PyArg_ParseTuple(args, "ip", &dim, &lists)) return NULL;
    return PyLong_FromSize_t(gr_edmd_bytes_per_particle(dim, lists));
}

static int check_ready(EDMDObject *self)
{
    if (!self->sim) {
        PyErr_SetString(PyExc_RuntimeError, "EDMD was not initialised");
        return 0;
    }
    if (self->busy) {
        PyErr_SetString(PyExc_RuntimeError, "this simulation is running in another thread");
        return 0;
    }
    return 1;
}

/* An output buffer: None, or a writeable C-contiguous array of the given dtype and size, in
 * the machine's byte order (the type number alone does not say: ">f8" is NPY_FLOAT64 too). */
static int out_buffer(PyObject *obj, const char *name, int type, npy_intp size, void **data)
{
    *data = NULL;
    if (obj == Py_None) return 1;
    if (!PyArray_Check(obj) || PyArray_TYPE((PyArrayObject *)obj) != type ||
        !PyArray_ISNOTSWAPPED((PyArrayObject *)obj) ||
        !PyArray_IS_C_CONTIGUOUS((PyArrayObject *)obj) ||
        !PyArray_ISWRITEABLE((PyArrayObject *)obj) ||
        PyArray_SIZE((PyArrayObject *)obj) != size) {
        PyErr_Format(PyExc_ValueError, "%s must be a writeable C-contiguous native-order %s array of %zd elements",
                     name, type == NPY_FLOAT64 ? "float64" : "int64", (Py_ssize_t)size);
        return 0;
    }
    *data = PyArray_DATA((PyArrayObject *)obj);
    return 1;
}

static PyObject *EDMD_advance(EDMDObject *self, PyObject *args, PyObject *kw)
{
    /* the stop criteria and the chunk's budget, then the sample times and the buffers
     * (None: not sampled) */
    static char *names[] = {"t_stop", "collisions_per_particle", "stop_kinetic_energy",
                            "max_events", "sample_times", "next", "positions", "velocities",
                            "kinetic_energy", "momentum", "pair_collisions", "wall_collisions",
                            "virial", "wall_impulse",
                            "stress_collisional", "kinetic_time_tensor", "kinetic_tensor", "angular_velocities",
                            "wall_work", "collision_loss",
                            NULL};
    gr_edmd_stop stop;
    long long max_events, next;
    PyObject *otimes, *opos = Py_None, *ovel = Py_None, *okin = Py_None, *omom = Py_None,
             *opair = Py_None, *owall = Py_None, *ovir = Py_None, *oimp = Py_None,
             *ostc = Py_None, *ostk = Py_None, *okt = Py_None, *ospin = Py_None;
    PyObject *owork = Py_None, *oloss = Py_None; /* a vibrating wall's books */
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|$dddLOLOOOOOOOOOOOOOO:advance", names, &stop.t_stop,
                                     &stop.collisions_per_particle, &stop.kinetic_energy,
                                     &max_events, &otimes, &next, &opos, &ovel, &okin, &omom,
                                     &opair, &owall, &ovir, &oimp, &ostc, &ostk, &okt, &ospin,
                                     &owork, &oloss) ||
        require_keywords(args, kw, names, 6, "advance") < 0)
        return NULL;
    if (!check_ready(self)) return NULL;
    if (max_events <= 0) {
        PyErr_SetString(PyExc_ValueError, "max_events must be positive");
        return NULL;
    }
    if (stop.t_stop != stop.t_stop || stop.kinetic_energy != stop.kinetic_energy) {
        PyErr_SetString(PyExc_ValueError, "t_stop and stop_kinetic_energy must not be NaN");
        return NULL;
    }
    stop.energy = stop.kinetic_energy >= 0.0; /* negative: no energy criterion */
    stop.max_events = max_events;
    npy_intp any1[1] = {-1};
    PyArrayObject *times = as_f64(otimes, "sample_times", 1, any1);
    if (!times) return NULL;
    npy_intp T = PyArray_DIM(times, 0);
    gr_edmd_samples smp;
    memset(&smp, 0, sizeof smp);
    smp.count = T;
    smp.times = PyArray_DATA(times);
    smp.next = next;
    if (next < 0 || next > T) {
        PyErr_SetString(PyExc_ValueError, "next must lie in [0, len(sample_times)]");
        Py_DECREF(times);
        return NULL;
    }
    npy_intp nd, td, tdd, nw;
    if (!mul_size(T, self->n, &nd, "positions") || !mul_size(nd, self->dim, &nd, "positions") ||
        !mul_size(T, self->dim, &td, "momentum") ||
        !mul_size(td, self->dim, &tdd, "stress_collisional") ||
        !mul_size(T, self->n, &nw, "angular_velocities") ||
        !mul_size(nw, self->dim == 2 ? 1 : 3, &nw, "angular_velocities")) {
        Py_DECREF(times);
        return NULL;
    }
    if (!out_buffer(opos, "positions", NPY_FLOAT64, nd, (void **)&smp.pos) ||
        !out_buffer(ovel, "velocities", NPY_FLOAT64, nd, (void **)&smp.vel) ||
        !out_buffer(okin, "kinetic_energy", NPY_FLOAT64, T, (void **)&smp.kinetic) ||
        !out_buffer(omom, "momentum", NPY_FLOAT64, td, (void **)&smp.momentum) ||
        !out_buffer(opair, "pair_collisions", NPY_INT64, T, (void **)&smp.pair) ||
        !out_buffer(owall, "wall_collisions", NPY_INT64, T, (void **)&smp.wall) ||
        !out_buffer(ovir, "virial", NPY_FLOAT64, T, (void **)&smp.virial) ||
        !out_buffer(oimp, "wall_impulse", NPY_FLOAT64, T, (void **)&smp.wall_impulse) ||
        !out_buffer(ostc, "stress_collisional", NPY_FLOAT64, tdd, (void **)&smp.stress_collisional) ||
        !out_buffer(ostk, "kinetic_time_tensor", NPY_FLOAT64, tdd, (void **)&smp.kinetic_time_tensor) ||
        !out_buffer(okt, "kinetic_tensor", NPY_FLOAT64, tdd, (void **)&smp.kinetic_tensor) ||
        !out_buffer(ospin, "angular_velocities", NPY_FLOAT64, nw, (void **)&smp.spin) ||
        !out_buffer(owork, "wall_work", NPY_FLOAT64, T, (void **)&smp.wall_work) ||
        !out_buffer(oloss, "collision_loss", NPY_FLOAT64, T, (void **)&smp.collision_loss)) {
        Py_DECREF(times);
        return NULL;
    }
    gr_error err = {0, -1, -1, NAN, NAN, NULL};
    int status;
    self->busy = 1;
    Py_BEGIN_ALLOW_THREADS
    status = gr_edmd_advance(self->sim, &stop, &smp, &err);
    Py_END_ALLOW_THREADS
    self->busy = 0;
    Py_DECREF(times);
    if (status < 0) return raise_status(status, &err);
    return Py_BuildValue("(iL)", status, (long long)smp.next);
}

static PyObject *EDMD_state(EDMDObject *self, PyObject *Py_UNUSED(ignored))
{
    if (!check_ready(self)) return NULL;
    npy_intp shp[2] = {self->n, self->dim};
    PyObject *pos = PyArray_SimpleNew(2, shp, NPY_FLOAT64);
    PyObject *vel = PyArray_SimpleNew(2, shp, NPY_FLOAT64);
    PyObject *img = PyArray_SimpleNew(2, shp, NPY_INT64);
    if (!pos || !vel || !img) {
        Py_XDECREF(pos);
        Py_XDECREF(vel);
        Py_XDECREF(img);
        return NULL;
    }
    gr_edmd_state(self->sim, PyArray_DATA((PyArrayObject *)pos),
                  PyArray_DATA((PyArrayObject *)vel), PyArray_DATA((PyArrayObject *)img));
    return Py_BuildValue("(NNN)", pos, vel, img);
}

/* The rough particles' angular velocities now: (N,) in 2D, (N, 3) in 3D; None for smooth
 * particles. */
static PyObject *EDMD_angular_velocities(EDMDObject *self, PyObject *Py_UNUSED(ignored))
{
    if (!check_ready(self)) return NULL;
    if (!gr_edmd_has_spin(self->sim)) Py_RETURN_NONE;
    npy_intp shp[2] = {self->n, 3};
    PyObject *out = PyArray_SimpleNew(self->dim == 2 ? 1 : 2, shp, NPY_FLOAT64);
    if (!out) return NULL;
    gr_edmd_spin(self->sim, PyArray_DATA((PyArrayObject *)out));
    return out;
}

static PyObject *EDMD_counters(EDMDObject *self, PyObject *Py_UNUSED(ignored))
{
    if (!check_ready(self)) return NULL;
    gr_edmd_counters c;
    gr_edmd_get_counters(self->sim, &c);
#define NINE(x) x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8]
    PyObject *out = Py_BuildValue("{s:d,s:L,s:L,s:L,s:L,s:L,s:L,s:L,s:L,s:d,s:d,s:d,s:d,s:(iii),s:d,s:d,s:L,s:d,s:d,s:d}", "time", c.t,
                         "events", (long long)c.events, "pair_collisions", (long long)c.pair,
                         "wall_collisions", (long long)c.wall, "cell_crossings",
                         (long long)c.crossings, "shell_exits", (long long)c.shell_exits,
                         "stale_events", (long long)c.invalid,
                         "tc_elastic_collisions", (long long)c.elastic_tc,
                         "law_clamped_collisions", (long long)c.law_clamped, "virial", c.virial,
                         "wall_impulse", c.wall_impulse, "kinetic_energy", c.kinetic,
                         "kinetic_time_integral", c.kinetic_time, "cells",
                         c.ncell[0], c.ncell[1], c.ncell[2], "shell", c.shell,
                         "shear_work", c.shear_work, "kicks", (long long)c.kicks,
                         "drive_energy", c.drive_energy, "wall_work", c.wall_work,
                         "collision_loss", c.collision_loss);
    /* the stress tensor's parts: nine numbers each, of which the first dim * dim are the
     * dim x dim tensor row-major (zeros unless built with stress) */
    PyObject *st = out ? Py_BuildValue("{s:(ddddddddd),s:(ddddddddd),s:(ddddddddd)}",
                                       "stress_collisional", NINE(c.stress_collisional),
                                       "kinetic_time_tensor", NINE(c.kinetic_time_tensor),
                                       "kinetic_tensor", NINE(c.kinetic_tensor))
                       : NULL;
#undef NINE
    if (!st || PyDict_Update(out, st) < 0) {
        Py_XDECREF(st);
        Py_XDECREF(out);
        return NULL;
    }
    Py_DECREF(st);
    return out;
}

/* ---- checkpoints (csrc/checkpoint.c) ---- */

static PyObject *EDMD_save_state(EDMDObject *self, PyObject *Py_UNUSED(ignored))
{
    if (!check_ready(self)) return NULL;
    const size_t size = gr_edmd_save_size(self->sim);
    if (size > (size_t)PY_SSIZE_T_MAX) return PyErr_NoMemory();
    PyObject *out = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)size);
    if (!out) return NULL;
    int status;
    self->busy = 1; /* no advance() while the state is read without the GIL */
    Py_BEGIN_ALLOW_THREADS
    status = gr_edmd_save(self->sim, (unsigned char *)PyBytes_AS_STRING(out), size);
    Py_END_ALLOW_THREADS
    self->busy = 0;
    if (status != GR_OK) {
        Py_DECREF(out);
        return raise_status(status, NULL);
    }
    return out;
}

static PyObject *EDMD_restore_state(EDMDObject *self, PyObject *arg)
{
    if (!check_ready(self)) return NULL;
    Py_buffer view;
    if (PyObject_GetBuffer(arg, &view, PyBUF_SIMPLE) < 0) return NULL;
    gr_error err = {0, -1, -1, NAN, NAN, NULL};
    int status;
    self->busy = 1;
    Py_BEGIN_ALLOW_THREADS
    status = gr_edmd_restore(self->sim, view.buf, (size_t)view.len, &err);
    Py_END_ALLOW_THREADS
    self->busy = 0;
    PyBuffer_Release(&view);
    if (status != GR_OK) return raise_status(status, &err);
    Py_RETURN_NONE;
}

static PyMethodDef EDMD_methods[] = {
    {"advance", (PyCFunction)(void (*)(void))EDMD_advance, METH_VARARGS | METH_KEYWORDS,
     "advance(*, t_stop, collisions_per_particle, stop_kinetic_energy, max_events,"
     " sample_times, next, positions=None, velocities=None, kinetic_energy=None,"
     " momentum=None, pair_collisions=None, wall_collisions=None, virial=None,"
     " wall_impulse=None, stress_collisional=None, kinetic_time_tensor=None,"
     " kinetic_tensor=None, angular_velocities=None, wall_work=None,"
     " collision_loss=None) -> (reason, next).  Process events,"
     " writing samples into the arrays given (stop_kinetic_energy: the mean translational"
     " kinetic energy to stop at, negative for none)."},
    {"angular_velocities", (PyCFunction)EDMD_angular_velocities, METH_NOARGS,
     "angular_velocities() -> the rough particles' spins now ((N,) in 2D, (N, 3) in 3D), or"
     " None for smooth particles"},
    {"state", (PyCFunction)EDMD_state, METH_NOARGS,
     "state() -> (positions wrapped in the box, velocities, image counters) at the current time"},
    {"counters", (PyCFunction)EDMD_counters, METH_NOARGS, "counters() -> dict"},
    {"save_state", (PyCFunction)EDMD_save_state, METH_NOARGS,
     "save_state() -> bytes: the engine's whole state (csrc/checkpoint.h)"},
    {"restore_state", (PyCFunction)EDMD_restore_state, METH_O,
     "restore_state(bytes): replace the state by a saved one; the engine must have been built"
     " from the same scene and knobs.  ValueError names what does not fit."},
    {NULL, NULL, 0, NULL}
};

static PyTypeObject EDMDType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "granular._core.EDMD",
    .tp_basicsize = sizeof(EDMDObject),
    .tp_dealloc = (destructor)EDMD_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    /* the signature line (before "--") is what inspect and stubtest read */
    .tp_doc = "EDMD(*, cell_factor=1.0, big_ratio=BIG_RATIO, shell=0.0, stress=False, **scene)\n--\n\n"
              "Event-driven MD engine (internal: use granular.Simulation).  The scene's "
              "keywords are EDMD_KEYWORDS (Scene._engine_keywords gives them).",
    .tp_methods = EDMD_methods,
    .tp_init = (initproc)EDMD_init,
    .tp_new = PyType_GenericNew,
};

/* ==== EDMD binding end ============================================================== */


/* (the two engines' bindings are kept apart so each can grow on its own) */



/* ==== SDE binding begin ============================================================= */

/* A writeable C-contiguous array of the given type and total size (for in/out buffers). */
static void *inout(PyObject *obj, const char *name, int type, npy_intp size)
{
    void *data = NULL;
    if (obj == Py_None) {
        PyErr_Format(PyExc_ValueError, "%s is required", name);
        return NULL;
    }
    return out_buffer(obj, name, type, size, &data) ? data : NULL;
}

/* Doubles of ring for the lags (each >= 1, increasing), or -1 with an exception set. */
static int64_t ring_size_of(int dim, npy_intp L, const int64_t *lags, int estimator)
{
    for (npy_intp l = 0; l < L; l++)
        if (lags[l] < 1 || (l > 0 && lags[l] <= lags[l - 1])) {
            PyErr_SetString(PyExc_ValueError, "lags must be increasing and >= 1 step");
            return -1;
        }
    if (estimator != GR_TAMSD_STRIDED && estimator != GR_TAMSD_ALL) {
        PyErr_Format(PyExc_ValueError, "tamsd_estimator must be 0 (strided) or 1 (all), got %d",
                     estimator);
        return -1;
    }
    int64_t size = gr_tamsd_ring_size(dim, L, lags, estimator);
    if (size < 0)
        PyErr_Format(PyExc_ValueError, "the every-window TAMSD keeps the last lag's worth of "
                     "positions: lags up to %lld steps (take the strided estimator)",
                     (long long)GR_TAMSD_ALL_MAX_LAG);
    return size;
}

static PyObject *sde_run(PyObject *Py_UNUSED(module), PyObject *args, PyObject *kw)
{
    static char *names[] = {"dim", "model", "scheme", "gamma0", "D0", "tau0", "dt", "key",
                            "n", "first", "step_from", "step_to", "n_steps", "x", "v",
                            "sample_steps", "x2", "v2", "positions", "lags", "tamsd", "ring",
                            "carry", "threads", "tamsd_estimator", "exponent", "accel",
                            "stiffness", "origin", NULL};
    gr_sde_config cfg;
    memset(&cfg, 0, sizeof cfg); /* no external force unless accel or stiffness is given */
    cfg.exponent = 1.0; /* UDSBM's (1 + t/tau0)^-exponent: optional, the thesis' 1 */
    PyObject *oaccel = Py_None, *ostiff = Py_None, *oorigin = Py_None;
    unsigned long long key;
    long long n, first, step_from, step_to, n_steps;
    PyObject *ox, *ov, *osteps, *ox2, *ov2, *opos, *olags, *otamsd, *oring, *ocarry = Py_None;
    int threads = 1, estimator = GR_TAMSD_STRIDED;
    /* every argument a keyword, the first 22 required (see require_keywords) */
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|$iiiddddKLLLLLOOOOOOOOOOiidOOO:sde_run", names,
                                     &cfg.dim, &cfg.model, &cfg.scheme, &cfg.gamma0, &cfg.D0,
                                     &cfg.tau0, &cfg.dt, &key, &n, &first, &step_from, &step_to,
                                     &n_steps, &ox, &ov, &osteps, &ox2, &ov2, &opos, &olags,
                                     &otamsd, &oring, &ocarry, &threads, &estimator,
                                     &cfg.exponent, &oaccel, &ostiff, &oorigin) ||
        require_keywords(args, kw, names, 22, "sde_run") < 0)
        return NULL;
    if (!(cfg.exponent > 0.0 && cfg.exponent < INFINITY)) {
        PyErr_SetString(PyExc_ValueError, "exponent must be positive and finite");
        return NULL;
    }
    if (threads < 1) {
        PyErr_Format(PyExc_ValueError, "threads must be >= 1, got %d", threads);
        return NULL;
    }
    if (threads > 256) threads = 256; /* more than any machine's cores: no thread per block */
    cfg.key = key;
    if (cfg.dim < 1 || cfg.dim > 3 || n < 0 || first < 0) {
        PyErr_SetString(PyExc_ValueError, "dim must be 1..3 and n, first non-negative");
        return NULL;
    }
    if (n_steps < 0 || n_steps > GR_SDE_MAX_STEPS) {
        PyErr_Format(PyExc_ValueError, "n_steps must lie in [0, 2**62], got %lld", n_steps);
        return NULL;
    }
    if (step_from < 0 || step_from > step_to || step_to > n_steps) {
        PyErr_Format(PyExc_ValueError, "need 0 <= step_from <= step_to <= n_steps, got %lld, %lld, %lld",
                     step_from, step_to, n_steps);
        return NULL;
    }
    if (!PyArray_Check(ox) || !PyArray_Check(osteps) || !PyArray_Check(olags) ||
        PyArray_TYPE((PyArrayObject *)osteps) != NPY_INT64 ||
        PyArray_TYPE((PyArrayObject *)olags) != NPY_INT64 ||
        !PyArray_ISNOTSWAPPED((PyArrayObject *)osteps) ||
        !PyArray_ISNOTSWAPPED((PyArrayObject *)olags) ||
        !PyArray_IS_C_CONTIGUOUS((PyArrayObject *)osteps) ||
        !PyArray_IS_C_CONTIGUOUS((PyArrayObject *)olags)) {
        PyErr_SetString(PyExc_ValueError,
                        "x must be an array; sample_steps and lags C-contiguous native-order int64 arrays");
        return NULL;
    }
    const npy_intp d = cfg.dim;
    const npy_intp count = PyArray_SIZE((PyArrayObject *)ox) / d; /* count * d <= len(x) */
    const npy_intp T = PyArray_SIZE((PyArrayObject *)osteps);
    const npy_intp L = PyArray_SIZE((PyArrayObject *)olags);
    if (first > n || count > n - first) {
        PyErr_SetString(PyExc_ValueError, "first + len(x) exceeds n");
        return NULL;
    }
    if (!(step_from == 0 && step_to == n_steps) && count > 1) {
        PyErr_SetString(PyExc_ValueError, "a segment of a run (not steps 0 to n_steps) takes one "
                        "particle: its ring of past positions carries over to the next segment");
        return NULL;
    }
    /* every size in checked arithmetic: n and the counts come from the caller */
    npy_intp td, tnd = 0, nl;
    if (!mul_size(T, d, &td, "x2") || !mul_size(n, L, &nl, "tamsd") ||
        (opos != Py_None && (!mul_size(T, n, &tnd, "positions") || !mul_size(tnd, d, &tnd, "positions"))))
        return NULL;
    gr_sde_output out;
    memset(&out, 0, sizeof out);
    out.n_samples = T;
    out.sample_steps = PyArray_DATA((PyArrayObject *)osteps);
    out.n_lags = L;
    out.lags = PyArray_DATA((PyArrayObject *)olags);
    out.estimator = estimator;
    const int64_t ring_size = ring_size_of(cfg.dim, L, out.lags, estimator);
    if (ring_size < 0) return NULL;
    double *x = inout(ox, "x", NPY_FLOAT64, count * d);
    double *v = x ? inout(ov, "v", NPY_FLOAT64, count * d) : NULL;
    out.x2 = v ? inout(ox2, "x2", NPY_FLOAT64, td) : NULL;
    out.v2 = out.x2 ? inout(ov2, "v2", NPY_FLOAT64, td) : NULL;
    out.tamsd = out.v2 ? inout(otamsd, "tamsd", NPY_FLOAT64, nl) : NULL;
    out.ring = out.tamsd ? inout(oring, "ring", NPY_FLOAT64, ring_size) : NULL;
    if (!out.ring) return NULL;
    if (opos != Py_None && !(out.positions = inout(opos, "positions", NPY_FLOAT64, tnd)))
        return NULL;
    npy_intp tdd;
    if (ocarry != Py_None && (!mul_size(td, 2, &tdd, "carry") ||
                              !(out.carry = inout(ocarry, "carry", NPY_FLOAT64, tdd))))
        return NULL;
    /* external forces (sde.h): accel and stiffness dim doubles each, origin count x dim */
    if (oaccel != Py_None || ostiff != Py_None || oorigin != Py_None) {
        const double *a = oaccel == Py_None ? NULL : inout(oaccel, "accel", NPY_FLOAT64, d);
        const double *k = ostiff == Py_None ? NULL : inout(ostiff, "stiffness", NPY_FLOAT64, d);
        if ((oaccel != Py_None && !a) || (ostiff != Py_None && !k)) return NULL;
        if (oorigin != Py_None && !(cfg.origin = inout(oorigin, "origin", NPY_FLOAT64, count * d)))
            return NULL;
        cfg.force = 1;
        for (npy_intp i = 0; i < d; i++) {
            cfg.accel[i] = a ? a[i] : 0.0;
            cfg.stiffness[i] = k ? k[i] : 0.0;
        }
    }
    for (npy_intp k = 0; k < T; k++)
        if (out.sample_steps[k] < 0 || (k > 0 && out.sample_steps[k] <= out.sample_steps[k - 1])) {
            PyErr_SetString(PyExc_ValueError, "sample_steps must be increasing and >= 0");
            return NULL;
        }
    /* the per-step coefficient table of exact UDSBM (and of EM for an exponent != 1),
     * shared by the call's particles: only worth it for several, and only when not too
     * large (else, or if the allocation fails, the core computes the coefficients inline:
     * slower, the same numbers).  The bound keeps 5 x steps + 1 far from overflowing. */
    double *coef = NULL;
    const int64_t seg = step_to - step_from;
    if (cfg.model == GR_SDE_UDSBM && (cfg.scheme == GR_SDE_EXACT || cfg.exponent != 1.0) &&
        count > 1 && seg <= (1LL << 22))
        coef = PyMem_Calloc((size_t)(5 * seg + 1), sizeof(double));
    out.step_coef = coef;
    gr_error err = {0, -1, -1, NAN, NAN, NULL};
    int status;
    Py_BEGIN_ALLOW_THREADS
    status = gr_sde_run(&cfg, n, first, count, step_from, step_to, n_steps, x, v, &out, threads,
                        &err);
    Py_END_ALLOW_THREADS
    PyMem_Free(coef);
    if (status != GR_OK) return raise_status(status, &err);
    Py_RETURN_NONE;
}

static PyObject *sde_ring_size(PyObject *Py_UNUSED(module), PyObject *args)
{
    int dim, estimator = GR_TAMSD_STRIDED;
    PyObject *olags;
    if (!PyArg_ParseTuple(args, "iO|i", &dim, &olags, &estimator)) return NULL;
    if (dim < 1 || dim > 3) {
        PyErr_SetString(PyExc_ValueError, "dim must be 1..3");
        return NULL;
    }
    PyArrayObject *lags = (PyArrayObject *)PyArray_FROMANY(olags, NPY_INT64, 1, 1, NPY_ARRAY_IN_ARRAY);
    if (!lags) return NULL;
    int64_t size = ring_size_of(dim, PyArray_SIZE(lags), PyArray_DATA(lags), estimator);
    Py_DECREF(lags);
    return size < 0 ? NULL : PyLong_FromLongLong(size);
}

static PyObject *sde_lag_stride(PyObject *Py_UNUSED(module), PyObject *args)
{
    long long lag;
    int estimator = GR_TAMSD_STRIDED;
    if (!PyArg_ParseTuple(args, "L|i", &lag, &estimator)) return NULL;
    if (lag < 1) {
        PyErr_SetString(PyExc_ValueError, "lag must be >= 1");
        return NULL;
    }
    if (estimator != GR_TAMSD_STRIDED && estimator != GR_TAMSD_ALL) {
        PyErr_SetString(PyExc_ValueError, "tamsd_estimator must be 0 (strided) or 1 (all)");
        return NULL;
    }
    return PyLong_FromLongLong(gr_tamsd_stride(lag, estimator));
}

static PyObject *sde_force_step(PyObject *Py_UNUSED(module), PyObject *args)
{
    double g, D, w, dt, c[6];
    if (!PyArg_ParseTuple(args, "dddd", &g, &D, &w, &dt)) return NULL;
    if (!(g > 0.0) || !(D > 0.0) || !(w >= 0.0) || !(dt > 0.0) || !isfinite(g) ||
        !isfinite(D) || !isfinite(w) || !isfinite(dt)) {
        PyErr_SetString(PyExc_ValueError, "need gamma, D, dt > 0 and w >= 0, all finite");
        return NULL;
    }
    gr_sde_force_step(g, D, w, dt, c);
    return Py_BuildValue("(dddddd)", c[0], c[1], c[2], c[3], c[4], c[5]);
}

/* ==== SDE binding end =============================================================== */

/* ------------------------------------------------------------------------------------ */
/* Module                                                                                 */
/* ------------------------------------------------------------------------------------ */

static PyMethodDef core_methods[] = {
    /* the event-driven engine's rules, owned by the C core */
    {"edmd_check", (PyCFunction)(void (*)(void))edmd_check, METH_VARARGS | METH_KEYWORDS,
     "edmd_check(*, same keywords as EDMD): the checks of EDMD() without building it"},
    {"big_cut", big_cut, METH_VARARGS,
     "big_cut(radii, big_ratio): particles wider than this are big"},
    {"big_particles", big_particles, METH_VARARGS,
     "big_particles(radii, lengths, big_ratio, cell_factor): which the cell grid keeps out"},
    {"edmd_bytes_per_particle", edmd_bytes_per_particle, METH_VARARGS,
     "edmd_bytes_per_particle(dim, lists): what the engine allocates per particle"},
    /* ==== SDE methods begin ==== */
    {"sde_run", (PyCFunction)(void (*)(void))sde_run, METH_VARARGS | METH_KEYWORDS,
     "sde_run(*, dim, model, scheme, gamma0, D0, tau0, dt, key, n, first, step_from, step_to,"
     " n_steps, x, v, sample_steps, x2, v2, positions, lags, tamsd, ring, carry=None,"
     " threads=1, tamsd_estimator=0, exponent=1.0, accel=None, stiffness=None, origin=None):"
     " advance particles first..first+len(x)"
     " over the steps [step_from, step_to) of a run of n_steps on `threads` threads,"
     " accumulating into the given arrays; ring (sde_ring_size doubles) carries one particle"
     " from segment to segment, carry (2 x len(sample_steps) x dim doubles) the sums of a"
     " block of particles left open; accel, stiffness (dim doubles: g, k/m) and origin"
     " (len(x) x dim: the starts relative to the trap's centre) add an external force"
     " (internal: use granular.langevin)."},
    {"sde_lag_stride", sde_lag_stride, METH_VARARGS,
     "sde_lag_stride(lag, tamsd_estimator=0): spacing of TAMSD window starts for a lag (steps;"
     " estimator 0 strided, 1 every window)"},
    {"sde_ring_size", sde_ring_size, METH_VARARGS,
     "sde_ring_size(dim, lags, tamsd_estimator=0): doubles of sde_run's ring for these lags"
     " (steps, increasing, each >= 1)"},
    {"sde_force_step", sde_force_step, METH_VARARGS,
     "sde_force_step(gamma, D, w, dt): the exact scheme's (e12, e22, j1, kx, sx, sv) of one axis"
     " under a force with stiffness per mass w (for the tests)"},
    /* ==== SDE methods end ==== */
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef core_module = {
    PyModuleDef_HEAD_INIT, "granular._core",
    "The C core of granular: event-driven MD and SDE integrators (internal; use granular).",
    -1, core_methods, NULL, NULL, NULL, NULL
};

/* A float constant of the module; 0, or -1 with an exception set. */
static int add_double(PyObject *m, const char *name, double value)
{
    PyObject *x = PyFloat_FromDouble(value);
    int status = x ? PyModule_AddObjectRef(m, name, x) : -1;
    Py_XDECREF(x);
    return status;
}

PyMODINIT_FUNC PyInit__core(void)
{
    import_array();
    errors_module = PyImport_ImportModule("granular.errors");
    if (!errors_module) return NULL;
    PyObject *m = PyModule_Create(&core_module);
    if (!m) return NULL;
    /* ==== EDMD type registration ==== */
    if (PyType_Ready(&EDMDType) < 0 || PyModule_AddObjectRef(m, "EDMD", (PyObject *)&EDMDType) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    PyModule_AddIntConstant(m, "STOP_TIME", GR_STOP_TIME);
    PyModule_AddIntConstant(m, "STOP_BUDGET", GR_STOP_BUDGET);
    PyModule_AddIntConstant(m, "STOP_COLLISIONS", GR_STOP_COLLISIONS);
    PyModule_AddIntConstant(m, "STOP_ENERGY", GR_STOP_ENERGY);
    PyModule_AddIntConstant(m, "STOP_IDLE", GR_STOP_IDLE);
    PyModule_AddIntConstant(m, "BIG_MAX", GR_BIG_MAX);
    PyModule_AddIntConstant(m, "HEADS_CACHED", (long)GR_HEADS_CACHED);
    PyObject *layout = PyLong_FromUnsignedLongLong(gr_checkpoint_layout());
    if (!layout || PyModule_AddObjectRef(m, "CHECKPOINT_LAYOUT", layout) < 0) {
        Py_XDECREF(layout);
        Py_DECREF(m);
        return NULL;
    }
    Py_DECREF(layout);
    PyObject *big_ratio = PyFloat_FromDouble(GR_BIG_RATIO);
    if (!big_ratio || PyModule_AddObjectRef(m, "BIG_RATIO", big_ratio) < 0) {
        Py_XDECREF(big_ratio);
        Py_DECREF(m);
        return NULL;
    }
    Py_DECREF(big_ratio);
    /* EDMD's keywords (edmd_names): granular/_scene_params.py's test reads them */
    Py_ssize_t count = 0;
    while (edmd_names[count]) count++;
    PyObject *keywords = PyTuple_New(count);
    for (Py_ssize_t i = 0; keywords && i < count; i++) {
        PyObject *name = PyUnicode_FromString(edmd_names[i]);
        if (!name) {
            Py_CLEAR(keywords);
            break;
        }
        PyTuple_SET_ITEM(keywords, i, name);
    }
    if (!keywords || PyModule_AddObjectRef(m, "EDMD_KEYWORDS", keywords) < 0) {
        Py_XDECREF(keywords);
        Py_DECREF(m);
        return NULL;
    }
    Py_DECREF(keywords);
    /* ==== restitution laws (restitution.h): granular/restitution.py reads these ==== */
    if (PyModule_AddIntConstant(m, "LAW_CONSTANT", GR_LAW_CONSTANT) < 0 ||
        PyModule_AddIntConstant(m, "LAW_VISCOELASTIC", GR_LAW_VISCOELASTIC) < 0 ||
        PyModule_AddIntConstant(m, "LAW_TABLE", GR_LAW_TABLE) < 0 ||
        PyModule_AddIntConstant(m, "LAW_TABLE_MAX", GR_LAW_TABLE_MAX) < 0 ||
        add_double(m, "VISCO_C1", GR_VISCO_C1) < 0 || add_double(m, "VISCO_C2", GR_VISCO_C2) < 0 ||
        add_double(m, "VISCO_DELTA_MAX", GR_VISCO_DELTA_MAX) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    /* ==== random driving (drive.h): granular/driving.py reads these ==== */
    if (PyModule_AddIntConstant(m, "DRIVE_WHITE_NOISE", GR_DRIVE_WHITE_NOISE) < 0 ||
        PyModule_AddIntConstant(m, "DRIVE_THERMOSTAT", GR_DRIVE_THERMOSTAT) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    /* ==== SDE constants ==== */
    PyObject *max_steps = PyLong_FromLongLong(GR_SDE_MAX_STEPS);
    if (!max_steps || PyModule_AddObjectRef(m, "SDE_MAX_STEPS", max_steps) < 0) {
        Py_XDECREF(max_steps);
        Py_DECREF(m);
        return NULL;
    }
    Py_DECREF(max_steps);
    if (PyModule_AddIntConstant(m, "SDE_BLOCK", GR_SDE_BLOCK) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    gr_rng_init();
    gr_scan_init();
    /* which compilation of the neighbour-list scan runs here (edmd.c): for tests */
    if (PyModule_AddStringConstant(m, "SCAN_KERNEL", gr_scan_kernel()) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    /* which compilation of the batched normals runs here (rng.c): for tests and reports */
    if (PyModule_AddStringConstant(m, "RNG_KERNEL", gr_normal_batch_kernel()) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
