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

#include "common.h"
#include "edmd.h"
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
        return PyErr_NoMemory();
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
        snprintf(msg, sizeof msg,
                 "inelastic collapse at t = %.17g: particles %lld and %lld collide over and over "
                 "at one instant (%s); set contact_duration > 0 to use the TC model",
                 t, (long long)i, (long long)j, what[0] ? what : "events pile up");
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

/* ==== EDMD binding begin ============================================================ */
/* ==== EDMD binding end ============================================================== */


/* (the two engines' bindings are kept apart so each can grow on its own) */



/* ==== SDE binding begin ============================================================= */
/* ==== SDE binding end =============================================================== */

/* ------------------------------------------------------------------------------------ */
/* Module                                                                                 */
/* ------------------------------------------------------------------------------------ */

static PyMethodDef core_methods[] = {
    /* ==== SDE methods begin ==== */
    /* ==== SDE methods end ==== */
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef core_module = {
    PyModuleDef_HEAD_INIT, "granular._core",
    "The C core of granular: event-driven MD and SDE integrators (internal; use granular).",
    -1, core_methods
};

PyMODINIT_FUNC PyInit__core(void)
{
    import_array();
    errors_module = PyImport_ImportModule("granular.errors");
    if (!errors_module) return NULL;
    PyObject *m = PyModule_Create(&core_module);
    if (!m) return NULL;
    /* ==== EDMD type registration ==== */
    return m;
}
