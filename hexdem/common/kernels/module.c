/* hexdem.common._kernels: the kernels of kernels.h as Python functions. Each takes NumPy arrays
 * (or any C-ordered buffers) of float64 and int64 of the shapes kernels.h gives, writes its outputs
 * into arrays it is handed, and raises TypeError for an array of another type, order or shape. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <string.h>

#include "kernels.h"

#define MAX_ARGUMENTS 32

/* The buffers a call holds, released when it returns. */
typedef struct {
    Py_buffer views[MAX_ARGUMENTS];
    int count;
} Held;

static void release(Held *held)
{
    for (int k = 0; k < held->count; k++)
        PyBuffer_Release(&held->views[k]);
    held->count = 0;
}

/* Whether a buffer's format is a native 8-byte float ('d') or integer ('l', 'q'). */
static int has_type(const Py_buffer *view, char kind)
{
    const char *format = view->format ? view->format : "B";
    if (*format == '@' || *format == '=')
        format++;
    if (view->itemsize != 8 || strlen(format) != 1)
        return 0;
    return kind == 'd' ? *format == 'd' : (*format == 'l' || *format == 'q');
}

/* Argument `position` as a C-ordered array of kind 'd' (float64) or 'q' (int64) with `columns`
 * numbers a row (0: one axis; -1: two axes of any width, written into *columns_out), at least
 * `min_rows` rows, writable if `writable`; its data and rows into *data and *rows. */
static int take(Held *held, PyObject *const *args, int position, char kind, int columns, int writable,
                Py_ssize_t min_rows, void **data, Py_ssize_t *rows, Py_ssize_t *columns_out)
{
    Py_buffer *view = &held->views[held->count];
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(args[position], view, flags) != 0) {
        PyErr_Format(PyExc_TypeError, "argument %d: not a C-ordered%s array", position + 1,
                     writable ? " writable" : "");
        return -1;
    }
    held->count++;
    int ndim = columns == 0 ? 1 : 2;
    if (!has_type(view, kind) || view->ndim != ndim || (columns > 0 && view->shape[1] != columns)
        || view->shape[0] < min_rows) {
        PyErr_Format(PyExc_TypeError, "argument %d: expected %s %s of at least %zd rows", position + 1,
                     kind == 'd' ? "float64" : "int64", ndim == 1 ? "(n,)" : "(n, k)", min_rows);
        return -1;
    }
    *data = view->buf;
    if (rows)
        *rows = view->shape[0];
    if (columns_out)
        *columns_out = ndim == 2 ? view->shape[1] : 1;
    return 0;
}

static int count_ok(Py_ssize_t nargs, Py_ssize_t expected, const char *name)
{
    if (nargs == expected)
        return 1;
    PyErr_Format(PyExc_TypeError, "%s takes %zd arguments (%zd given)", name, expected, nargs);
    return 0;
}

static PyObject *index_error(const char *name)
{
    PyErr_Format(PyExc_IndexError, "%s: an index lies outside its array", name);
    return NULL;
}

#define TAKE(position, kind, columns, writable, min_rows, data, rows)                                       \
    if (take(&held, args, position, kind, columns, writable, min_rows, (void **)(data), rows, NULL) != 0)  \
        goto fail;

/* Argument `position` as a writable C-ordered float64 array of a ring's 3 slots, each of `width`
 * numbers: (3, width) exactly, the kernel's stride between slots. */
static int take_slots(Held *held, PyObject *const *args, int position, Py_ssize_t width, double **data)
{
    Py_ssize_t rows, columns;
    if (take(held, args, position, 'd', -1, 1, 3, (void **)data, &rows, &columns) != 0)
        return -1;
    if (rows != 3 || columns != width) {
        PyErr_Format(PyExc_TypeError, "argument %d: expected float64 (3, %zd)", position + 1, width);
        return -1;
    }
    return 0;
}

static PyObject *py_full_step_state(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Held held = {.count = 0};
    const double *positions, *velocities, *forces, *masses;
    double *x, *v;
    Py_ssize_t n;
    if (!count_ok(nargs, 7, "full_step_state"))
        return NULL;
    TAKE(3, 'd', 0, 0, 0, &masses, &n);
    TAKE(0, 'd', 3, 0, n, &positions, NULL);
    TAKE(1, 'd', 3, 0, n, &velocities, NULL);
    TAKE(2, 'd', 3, 0, n, &forces, NULL);
    TAKE(5, 'd', 2, 1, n, &x, NULL);
    TAKE(6, 'd', 2, 1, n, &v, NULL);
    double half_dt = PyFloat_AsDouble(args[4]);
    if (half_dt == -1.0 && PyErr_Occurred())
        goto fail;
    full_step_state(n, positions, velocities, forces, masses, half_dt, x, v);
    release(&held);
    Py_RETURN_NONE;
fail:
    release(&held);
    return NULL;
}

static PyObject *py_sample_pulses(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Held held = {.count = 0};
    SampleRows x;
    PulseArrays a;
    int64_t *complete;
    Py_ssize_t n_ids, n_previous, n_velocities, n, n_speeds, capacity;
    if (!count_ok(nargs, 30, "sample_pulses"))
        return NULL;
    TAKE(0, 'q', 0, 0, 0, &x.ids, &n_ids);
    TAKE(1, 'q', 0, 0, 0, &x.previous_ids, &n_previous);
    TAKE(2, 'd', 2, 0, 0, &x.velocities, &n_velocities);
    TAKE(3, 'q', 0, 0, 0, &x.rows, &n);
    TAKE(4, 'd', 2, 1, n, &x.end_velocity, NULL);
    TAKE(5, 'd', 0, 1, 0, &x.speeds, &n_speeds);
    if (n_speeds != 0 && n_speeds < n) {
        PyErr_SetString(PyExc_TypeError, "sample_pulses: speeds neither empty nor one a row");
        goto fail;
    }
    if (n_speeds == 0)
        x.speeds = NULL;
    x.n_ids = n_ids;
    x.n_previous = n_previous;
    x.n_velocities = n_velocities;
    if (take(&held, args, 17, 'd', -1, 1, n, (void **)&a.rec_value, NULL, &capacity) != 0)
        goto fail;
    if (capacity < 1) {
        PyErr_SetString(PyExc_TypeError, "sample_pulses: record ladders of no length");
        goto fail;
    }
    a.n = n;
    a.capacity = capacity;
    if (take_slots(&held, args, 9, n, &a.ring) != 0 || take_slots(&held, args, 27, 2 * n, &a.ring_velocity) != 0)
        goto fail;
    TAKE(10, 'd', 0, 1, n, &a.peak, NULL);
    TAKE(11, 'q', 0, 1, n, &a.peak_index, NULL);
    TAKE(12, 'd', 7, 1, n, &a.window, NULL);
    TAKE(13, 'q', 0, 1, n, &a.after, NULL);
    TAKE(14, 'q', 0, 1, n, &a.start, NULL);
    TAKE(15, 'q', 0, 1, n, &a.length, NULL);
    TAKE(16, 'q', (int)capacity, 1, n, &a.rec_index, NULL);
    TAKE(18, 'd', (int)capacity, 1, n, &a.rec_prev, NULL);
    TAKE(19, 'd', (int)capacity, 1, n, &a.rec_prev2, NULL);
    TAKE(20, 'q', (int)capacity, 1, n, &a.first_index, NULL);
    TAKE(21, 'd', (int)capacity, 1, n, &a.first_value, NULL);
    TAKE(22, 'd', (int)capacity, 1, n, &a.first_prev, NULL);
    TAKE(23, 'd', (int)capacity, 1, n, &a.first_prev2, NULL);
    TAKE(24, 'd', 7, 1, n, &a.rival, NULL);
    TAKE(25, 'q', 0, 1, n, &a.rival_index, NULL);
    TAKE(26, 'q', 0, 1, n, &a.rival_after, NULL);
    TAKE(28, 'd', 0, 1, n, &a.lazy_below, NULL);
    TAKE(29, 'q', 0, 1, n, &complete, NULL);
    long long s = PyLong_AsLongLong(args[6]);
    double q = PyFloat_AsDouble(args[7]), rival_ratio = PyFloat_AsDouble(args[8]);
    if (PyErr_Occurred())
        goto fail;
    int64_t count = sample_pulses(&x, s, q, rival_ratio, &a, complete);
    release(&held);
    if (count == -1)
        return index_error("sample_pulses");
    if (count == -2)
        Py_RETURN_NONE;
    return PyLong_FromLongLong(count);
fail:
    release(&held);
    return NULL;
}

static PyObject *py_audit_part(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Held held = {.count = 0};
    AuditRows a;
    double *sums;
    Py_ssize_t n_rows, n_own, n_spins, n_pairs, n_walls, n_members;
    if (!count_ok(nargs, 26, "audit_part"))
        return NULL;
    a.n_regions = PyLong_AsLongLong(args[24]);
    a.distance = PyFloat_AsDouble(args[4]);
    if (PyErr_Occurred())
        goto fail;
    if (a.n_regions < 0) {
        PyErr_SetString(PyExc_ValueError, "audit_part: a negative count of regions");
        goto fail;
    }
    TAKE(0, 'd', 2, 0, 0, &a.positions, &n_rows);
    TAKE(3, 'd', 2, 0, n_rows, &a.listed_at, NULL);
    TAKE(11, 'd', 0, 0, 0, &a.masses, &n_own);
    TAKE(1, 'd', 2, 0, n_own, &a.velocities, NULL);
    TAKE(2, 'd', 0, 0, 0, &a.spins, &n_spins);
    TAKE(5, 'q', 0, 0, 0, &a.i, &n_pairs);
    TAKE(6, 'q', 0, 0, n_pairs, &a.j, NULL);
    TAKE(7, 'd', 0, 0, n_pairs, &a.contact_m, NULL);
    TAKE(8, 'd', 0, 0, n_pairs, &a.coefficient, NULL);
    TAKE(9, 'q', 0, 0, n_pairs, &a.region_i, NULL);
    TAKE(10, 'q', 0, 0, n_pairs, &a.region_j, NULL);
    TAKE(12, 'd', 0, 0, n_own, &a.inertia, NULL);
    TAKE(13, 'q', 0, 0, n_own, &a.regions, NULL);
    TAKE(14, 'd', 2, 0, n_own, &a.start, NULL);
    TAKE(15, 'd', 2, 0, n_own, &a.external, NULL);
    TAKE(17, 'q', 0, 0, 0, &a.curved, &n_walls);
    TAKE(16, 'q', 0, 0, n_walls + 1, &a.bounds, NULL);
    TAKE(18, 'd', 2, 0, n_walls, &a.points, NULL);
    TAKE(19, 'd', 0, 0, n_walls, &a.lengths, NULL);
    TAKE(20, 'q', 0, 0, 0, &a.rows, &n_members);
    TAKE(21, 'd', 0, 0, n_members, &a.radii, NULL);
    TAKE(22, 'd', 0, 0, n_members, &a.wall_coefficient, NULL);
    TAKE(23, 'q', 0, 0, n_members, &a.wall_regions, NULL);
    TAKE(25, 'd', 0, 1, 3 + 2 * a.n_regions, &sums, NULL);
    if (n_spins && n_spins < n_own) {
        PyErr_SetString(PyExc_TypeError, "audit_part: fewer spins than audited rows");
        goto fail;
    }
    for (Py_ssize_t w = 0; w < n_walls; w++)
        if (a.bounds[w] < 0 || a.bounds[w] > a.bounds[w + 1] || a.bounds[w + 1] > n_members) {
            release(&held);
            return index_error("audit_part");
        }
    a.n_rows = n_rows;
    a.n_spins = n_spins;
    a.n_own = n_own;
    a.n_pairs = n_pairs;
    a.n_walls = n_walls;
    int status = audit_part(&a, sums);
    release(&held);
    if (status == -1)
        return index_error("audit_part");
    if (status == -2)
        return PyErr_NoMemory();
    return PyBool_FromLong(status);
fail:
    release(&held);
    return NULL;
}

static PyObject *py_pairs_within(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
    Held held = {.count = 0};
    const double *positions;
    int64_t *i, *j;
    Py_ssize_t n, capacity;
    if (!count_ok(nargs, 4, "pairs_within"))
        return NULL;
    TAKE(0, 'd', 2, 0, 0, &positions, &n);
    TAKE(2, 'q', 0, 1, 0, &i, &capacity);
    TAKE(3, 'q', 0, 1, capacity, &j, NULL);
    double cutoff = PyFloat_AsDouble(args[1]);
    if (cutoff == -1.0 && PyErr_Occurred())
        goto fail;
    int64_t found = pairs_within(n, positions, cutoff, capacity, i, j);
    release(&held);
    if (found == -1)
        return PyErr_NoMemory();
    if (found == -2) {
        PyErr_SetString(PyExc_ValueError, "pairs_within: a position or the cutoff is not finite");
        return NULL;
    }
    return PyLong_FromLongLong(found);
fail:
    release(&held);
    return NULL;
}

static PyMethodDef methods[] = {
    {"pairs_within", (PyCFunction)(void (*)(void))py_pairs_within, METH_FASTCALL,
     "pairs_within(positions, cutoff, i, j) -> the count of pairs within cutoff, the first len(i) written into i, j."},
    {"full_step_state", (PyCFunction)(void (*)(void))py_full_step_state, METH_FASTCALL,
     "full_step_state(positions, velocities, forces, masses, half_dt, x, v): the full-step sample into x, v."},
    {"sample_pulses", (PyCFunction)(void (*)(void))py_sample_pulses, METH_FASTCALL,
     "sample_pulses(ids, previous_ids, velocities, rows, end_velocity, speeds, s, q, rival_ratio, *state_arrays, "
     "complete) -> the count of rows written into complete, or None if ids are not previous_ids."},
    {"audit_part", (PyCFunction)(void (*)(void))py_audit_part, METH_FASTCALL,
     "audit_part(positions, velocities, spins, listed_at, distance, *row_constants, n_regions, sums) -> "
     "False if the contacts must be listed again, else True with sums written."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_kernels",
                                    "The in-run analysis's per-sample arithmetic, compiled (kernels.h).", -1, methods};

PyMODINIT_FUNC PyInit__kernels(void)
{
    return PyModule_Create(&module);
}
