/* hexdem.common._kernels: the kernels of kernels.h as Python callables whose every argument is
 * passed by name and checked by name, type and shape (binding.h): each kernel's table below names
 * its arguments and the shapes they must have. The tracker's state and the audit's row constants
 * are bound once (PulseArrays, AuditRows: objects that hold their arrays' buffers), and each sample
 * passes only its own arrays. */
#include "binding.h"

#include <string.h>

#include "kernels.h"

/* ---- full_step_state and pairs_within: one call each */

typedef struct {
    const double *positions, *velocities, *forces, *masses;
    double half_dt;
    double *x, *v;
} FullStepCall;

enum { FS_N, FS_SIZES };
_Static_assert(FS_SIZES <= MAX_SIZES, "FS_SIZES: more than MAX_SIZES");
static const char *const full_step_sizes[] = {"n"};
static const Field full_step_fields[] = {
    ARRAY("masses", 'd', FullStepCall, masses, SIZE(FS_N)),
    ARRAY2("positions", 'd', FullStepCall, positions, SIZE_AT_LEAST(FS_N), FIXED(3)),
    ARRAY2("velocities", 'd', FullStepCall, velocities, SIZE_AT_LEAST(FS_N), FIXED(3)),
    ARRAY2("forces", 'd', FullStepCall, forces, SIZE_AT_LEAST(FS_N), FIXED(3)),
    SCALAR("half_dt", 'f', FullStepCall, half_dt),
    OUT2("x", 'd', FullStepCall, x, SIZE(FS_N), FIXED(2)),
    OUT2("v", 'd', FullStepCall, v, SIZE(FS_N), FIXED(2)),
};
CHECKED(full_step_fields);
static Table full_step_table = {"full_step_state", full_step_fields, COUNT(full_step_fields), full_step_sizes, NULL};

static PyObject *py_full_step_state(PyObject *self, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames)
{
    Py_buffer views[COUNT(full_step_fields)];
    Py_ssize_t sizes[MAX_SIZES];
    FullStepCall c;
    int held;
    fresh_sizes(sizes);
    if (bind_arguments(&full_step_table, args, nargs, kwnames, &c, views, &held, sizes) != 0)
        return NULL;
    full_step_state(sizes[FS_N], c.positions, c.velocities, c.forces, c.masses, c.half_dt, c.x, c.v);
    release_views(views, &held);
    Py_RETURN_NONE;
}

typedef struct {
    const double *positions;
    double cutoff;
    int64_t *i, *j;
} PairsCall;

enum { PW_N, PW_CAPACITY, PW_SIZES };
_Static_assert(PW_SIZES <= MAX_SIZES, "PW_SIZES: more than MAX_SIZES");
static const char *const pairs_sizes[] = {"n", "capacity"};
static const Field pairs_fields[] = {
    ARRAY2("positions", 'd', PairsCall, positions, SIZE(PW_N), FIXED(2)),
    SCALAR("cutoff", 'f', PairsCall, cutoff),
    OUT("i", 'q', PairsCall, i, SIZE(PW_CAPACITY)),
    OUT("j", 'q', PairsCall, j, SIZE(PW_CAPACITY)),
};
CHECKED(pairs_fields);
static Table pairs_table = {"pairs_within", pairs_fields, COUNT(pairs_fields), pairs_sizes, NULL};

static PyObject *py_pairs_within(PyObject *self, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames)
{
    Py_buffer views[COUNT(pairs_fields)];
    Py_ssize_t sizes[MAX_SIZES];
    PairsCall c;
    int held;
    fresh_sizes(sizes);
    if (bind_arguments(&pairs_table, args, nargs, kwnames, &c, views, &held, sizes) != 0)
        return NULL;
    int64_t found = pairs_within(sizes[PW_N], c.positions, c.cutoff, sizes[PW_CAPACITY], c.i, c.j);
    release_views(views, &held);
    if (found == -1)
        return PyErr_NoMemory();
    if (found == -2) {
        PyErr_SetString(PyExc_ValueError, "pairs_within: a position or the cutoff is not finite");
        return NULL;
    }
    return PyLong_FromLongLong(found);
}

/* ---- PulseArrays: the tracker's state, and its sample */

/* Raised, with the state as it was, for a sample whose ids are not the previous sample's. */
static PyObject *BodiesReordered;

typedef struct {
    PulseArrays a;
    double q, rival_ratio;
} PulseBinding;

typedef struct {
    SampleRows x;
    int64_t *complete;
    int64_t s;
} SampleCall;

enum { P_N, P_CAPACITY, P_IDS, P_PREVIOUS, P_VELOCITIES, P_SPEEDS, P_SIZES };
_Static_assert(P_SIZES <= MAX_SIZES, "P_SIZES: more than MAX_SIZES");
static const char *const pulse_sizes[] = {"n", "capacity", "n_ids", "n_previous", "n_velocities", "n_speeds"};
/* The tracker writes every array of its state: each is bound writable, so that a read-only one is refused. */
#define P_STATE(name, kind, member) OUT(name, kind, PulseBinding, a.member, SIZE(P_N))
#define P_ROWS(name, kind, columns, member) OUT2(name, kind, PulseBinding, a.member, SIZE(P_N), columns)
static const Field pulse_fields[] = {
    P_STATE("peak", 'd', peak),
    P_ROWS("rec_value", 'd', SIZE(P_CAPACITY), rec_value),
    OUT2("ring_slots", 'd', PulseBinding, a.ring, FIXED(3), SIZE(P_N)),
    OUT2("velocity_slots", 'd', PulseBinding, a.ring_velocity, FIXED(3), {P_N, 2, 0, EXACT}),
    P_STATE("peak_index", 'q', peak_index),
    P_ROWS("window", 'd', FIXED(7), window),
    P_STATE("after", 'q', after),
    P_STATE("start", 'q', start),
    P_STATE("length", 'q', length),
    P_ROWS("rec_index", 'q', SIZE(P_CAPACITY), rec_index),
    P_ROWS("rec_prev", 'd', SIZE(P_CAPACITY), rec_prev),
    P_ROWS("rec_prev2", 'd', SIZE(P_CAPACITY), rec_prev2),
    P_ROWS("first_index", 'q', SIZE(P_CAPACITY), first_index),
    P_ROWS("first_value", 'd', SIZE(P_CAPACITY), first_value),
    P_ROWS("first_prev", 'd', SIZE(P_CAPACITY), first_prev),
    P_ROWS("first_prev2", 'd', SIZE(P_CAPACITY), first_prev2),
    P_ROWS("rival", 'd', FIXED(7), rival),
    P_STATE("rival_index", 'q', rival_index),
    P_STATE("rival_after", 'q', rival_after),
    P_STATE("lazy_below", 'd', lazy_below),
    SCALAR("q", 'f', PulseBinding, q),
    SCALAR("rival_ratio", 'f', PulseBinding, rival_ratio),
};
static const Field sample_fields[] = {
    ARRAY("ids", 'q', SampleCall, x.ids, SIZE(P_IDS)),
    ARRAY("previous_ids", 'q', SampleCall, x.previous_ids, SIZE(P_PREVIOUS)),
    ARRAY2("velocities", 'd', SampleCall, x.velocities, SIZE(P_VELOCITIES), FIXED(2)),
    ARRAY("rows", 'q', SampleCall, x.rows, SIZE(P_N)),
    OUT2("end_velocity", 'd', SampleCall, x.end_velocity, SIZE(P_N), FIXED(2)),
    {"speeds", 'd', 1, {{P_N, 1, 0, EMPTY_OR_AT_LEAST}, FIXED(0)}, 1, offsetof(SampleCall, x.speeds), P_SPEEDS},
    OUT("complete", 'q', SampleCall, complete, SIZE(P_N)),
    SCALAR("s", 'i', SampleCall, s),
};
CHECKED(pulse_fields);
static Table pulse_table = {"PulseArrays", pulse_fields, COUNT(pulse_fields), pulse_sizes, NULL};
CHECKED(sample_fields);
static Table sample_table = {"PulseArrays.sample", sample_fields, COUNT(sample_fields), pulse_sizes, NULL};

typedef struct {
    Bound head;
    PulseBinding c;
    Py_buffer views[COUNT(pulse_fields)];
} PulsesObject;


static PyObject *pulses_sample(PyObject *self, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames)
{
    PulsesObject *bound = (PulsesObject *)self;
    Py_buffer views[COUNT(sample_fields)];
    Py_ssize_t sizes[MAX_SIZES];
    SampleCall c;
    int held;
    memcpy(sizes, bound->head.sizes, sizeof sizes);
    if (bind_arguments(&sample_table, args, nargs, kwnames, &c, views, &held, sizes) != 0)
        return NULL;
    c.x.n_ids = sizes[P_IDS];
    c.x.n_previous = sizes[P_PREVIOUS];
    c.x.n_velocities = sizes[P_VELOCITIES];
    if (sizes[P_SPEEDS] == 0)
        c.x.speeds = NULL;
    int64_t count = sample_pulses(&c.x, c.s, bound->c.q, bound->c.rival_ratio, &bound->c.a, c.complete);
    release_views(views, &held);
    if (count == -1)
        return index_error("PulseArrays.sample");
    if (count == -2) {
        PyErr_SetString(BodiesReordered, "PulseArrays.sample: the sample's ids are not previous_ids");
        return NULL;
    }
    return PyLong_FromLongLong(count);
}

/* ---- AuditRows: the audit's row constants, and a sample's audit */

typedef struct {
    AuditRows a;
} AuditBinding;

typedef struct {
    const double *positions, *velocities, *spins;
    double *sums;
} AuditCall;

enum { A_ROWS, A_OWN, A_PAIRS, A_WALLS, A_MEMBERS, A_SPINS, A_SUMS, A_SIZES };
_Static_assert(A_SIZES <= MAX_SIZES, "A_SIZES: more than MAX_SIZES");
static const char *const audit_sizes[] = {"n_rows", "n_own", "n_pairs", "n_walls", "n_members", "n_spins", "n_sums"};
#define A_ARRAY(name, kind, size, member) ARRAY(name, kind, AuditBinding, a.member, SIZE(size))
static const Field audit_fields[] = {
    ARRAY2("listed_at", 'd', AuditBinding, a.listed_at, SIZE(A_ROWS), FIXED(2)),
    SCALAR("distance", 'f', AuditBinding, a.distance),
    A_ARRAY("i", 'q', A_PAIRS, i),
    A_ARRAY("j", 'q', A_PAIRS, j),
    A_ARRAY("contact_m", 'd', A_PAIRS, contact_m),
    A_ARRAY("coefficient", 'd', A_PAIRS, coefficient),
    A_ARRAY("region_i", 'q', A_PAIRS, region_i),
    A_ARRAY("region_j", 'q', A_PAIRS, region_j),
    A_ARRAY("masses", 'd', A_OWN, masses),
    A_ARRAY("inertia", 'd', A_OWN, inertia),
    A_ARRAY("regions", 'q', A_OWN, regions),
    ARRAY2("start", 'd', AuditBinding, a.start, SIZE(A_OWN), FIXED(2)),
    ARRAY2("external", 'd', AuditBinding, a.external, SIZE(A_OWN), FIXED(2)),
    A_ARRAY("curved", 'q', A_WALLS, curved),
    ARRAY("bounds", 'q', AuditBinding, a.bounds, {A_WALLS, 1, 1, EXACT}),
    ARRAY2("points", 'd', AuditBinding, a.points, SIZE(A_WALLS), FIXED(2)),
    A_ARRAY("lengths", 'd', A_WALLS, lengths),
    A_ARRAY("rows", 'q', A_MEMBERS, rows),
    A_ARRAY("radii", 'd', A_MEMBERS, radii),
    A_ARRAY("wall_coefficient", 'd', A_MEMBERS, wall_coefficient),
    A_ARRAY("wall_regions", 'q', A_MEMBERS, wall_regions),
    SCALAR("n_regions", 'i', AuditBinding, a.n_regions),
};
static const Field part_fields[] = {
    ARRAY2("positions", 'd', AuditCall, positions, SIZE(A_ROWS), FIXED(2)),
    ARRAY2("velocities", 'd', AuditCall, velocities, SIZE_AT_LEAST(A_OWN), FIXED(2)),
    {"spins", 'd', 1, {{A_OWN, 1, 0, EMPTY_OR_AT_LEAST}, FIXED(0)}, 0, offsetof(AuditCall, spins), A_SPINS},
    OUT("sums", 'd', AuditCall, sums, SIZE(A_SUMS)),
};
CHECKED(audit_fields);
static Table audit_table = {"AuditRows", audit_fields, COUNT(audit_fields), audit_sizes, NULL};
CHECKED(part_fields);
static Table part_table = {"AuditRows.part", part_fields, COUNT(part_fields), audit_sizes, NULL};

typedef struct {
    Bound head;
    AuditBinding c;
    Py_buffer views[COUNT(audit_fields)];
} AuditObject;

static PyObject *audit_part_of(PyObject *self, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames)
{
    AuditObject *bound = (AuditObject *)self;
    Py_buffer views[COUNT(part_fields)];
    Py_ssize_t sizes[MAX_SIZES];
    AuditCall c;
    int held;
    memcpy(sizes, bound->head.sizes, sizeof sizes);
    if (bind_arguments(&part_table, args, nargs, kwnames, &c, views, &held, sizes) != 0)
        return NULL;
    if (sizes[A_SUMS] != 3 + 2 * bound->c.a.n_regions) {
        PyErr_Format(PyExc_TypeError, "AuditRows.part: sums: expected float64 (3 + 2 n_regions,) = (%lld,)",
                     (long long)(3 + 2 * bound->c.a.n_regions));
        release_views(views, &held);
        return NULL;
    }
    AuditRows a = bound->c.a;
    a.positions = c.positions;
    a.velocities = c.velocities;
    a.spins = c.spins;
    a.n_spins = sizes[A_SPINS];
    int status = audit_part(&a, c.sums);
    release_views(views, &held);
    if (status == -1)
        return index_error("AuditRows.part");
    if (status == -2)
        return PyErr_NoMemory();
    return PyBool_FromLong(status);
}

static PyObject *pulses_new(PyTypeObject *type, PyObject *args, PyObject *kwargs)
{
    PyObject *self = bound_new(type, args, kwargs, &pulse_table, offsetof(PulsesObject, c),
                               offsetof(PulsesObject, views));
    if (self && ((PulsesObject *)self)->head.sizes[P_CAPACITY] < 1) {
        PyErr_SetString(PyExc_TypeError, "PulseArrays: record ladders of no length (capacity 0)");
        Py_CLEAR(self);
    }
    if (self) {
        PulsesObject *pulses = (PulsesObject *)self;
        pulses->c.a.n = pulses->head.sizes[P_N];
        pulses->c.a.capacity = pulses->head.sizes[P_CAPACITY];
    }
    return self;
}

static PyObject *audit_new(PyTypeObject *type, PyObject *args, PyObject *kwargs)
{
    PyObject *self = bound_new(type, args, kwargs, &audit_table, offsetof(AuditObject, c),
                               offsetof(AuditObject, views));
    if (!self)
        return NULL;
    AuditObject *audit = (AuditObject *)self;
    AuditRows *a = &audit->c.a;
    const Py_ssize_t *sizes = audit->head.sizes;
    if (a->n_regions < 0) {
        PyErr_SetString(PyExc_ValueError, "AuditRows: n_regions: a negative count of regions");
        Py_DECREF(self);
        return NULL;
    }
    a->n_rows = sizes[A_ROWS];
    a->n_own = sizes[A_OWN];
    a->n_pairs = sizes[A_PAIRS];
    a->n_walls = sizes[A_WALLS];
    for (Py_ssize_t w = 0; w < a->n_walls; w++)
        if (a->bounds[w] < 0 || a->bounds[w] > a->bounds[w + 1] || a->bounds[w + 1] > sizes[A_MEMBERS]) {
            Py_DECREF(self);
            return index_error("AuditRows: bounds");
        }
    return self;
}

static PyMethodDef pulses_methods[] = {
    {"sample", (PyCFunction)(void (*)(void))pulses_sample, METH_FASTCALL | METH_KEYWORDS,
     "sample(ids, previous_ids, velocities, rows, end_velocity, speeds, complete, s), all by name -> the count "
     "of rows written into complete; BodiesReordered if ids are not previous_ids (the state as it was)."},
    {NULL, NULL, 0, NULL},
};

static PyMethodDef audit_methods[] = {
    {"part", (PyCFunction)(void (*)(void))audit_part_of, METH_FASTCALL | METH_KEYWORDS,
     "part(positions, velocities, spins, sums), all by name -> False if the contacts must be listed again, "
     "else True with sums written."},
    {NULL, NULL, 0, NULL},
};

static PyTypeObject PulsesType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "hexdem.common._kernels.PulseArrays",
    .tp_basicsize = sizeof(PulsesObject),
    .tp_dealloc = bound_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "PulseArrays(the state's arrays, q, rival_ratio), all by name: the pulse tracker's state, its arrays "
              "checked and held; sample() takes a sample into it.",
    .tp_methods = pulses_methods,
    .tp_new = pulses_new,
};

static PyTypeObject AuditType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "hexdem.common._kernels.AuditRows",
    .tp_basicsize = sizeof(AuditObject),
    .tp_dealloc = bound_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "AuditRows(listed_at, distance, the row constants, n_regions), all by name: what the energy audit "
              "reads of a listing, checked and held; part() audits a sample.",
    .tp_methods = audit_methods,
    .tp_new = audit_new,
};

static PyMethodDef methods[] = {
    {"pairs_within", (PyCFunction)(void (*)(void))py_pairs_within, METH_FASTCALL | METH_KEYWORDS,
     "pairs_within(positions, cutoff, i, j), all by name -> the count of pairs within cutoff, the first len(i) "
     "written into i, j."},
    {"full_step_state", (PyCFunction)(void (*)(void))py_full_step_state, METH_FASTCALL | METH_KEYWORDS,
     "full_step_state(masses, positions, velocities, forces, half_dt, x, v), all by name: the full-step sample "
     "into x, v."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_kernels",
                                    "The in-run analysis's per-sample arithmetic, compiled (kernels.h).", -1, methods};

PyMODINIT_FUNC PyInit__kernels(void)
{
    Table *tables[] = {&full_step_table, &pairs_table, &pulse_table, &sample_table, &audit_table, &part_table};
    for (size_t t = 0; t < sizeof tables / sizeof tables[0]; t++)
        if (!tables[t]->names && intern_names(tables[t]) != 0)
            return NULL;
    if (PyType_Ready(&PulsesType) < 0 || PyType_Ready(&AuditType) < 0)
        return NULL;
    if (!BodiesReordered
        && !(BodiesReordered = PyErr_NewException("hexdem.common._kernels.BodiesReordered", PyExc_ValueError, NULL)))
        return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m)
        return NULL;
    if (PyModule_AddObjectRef(m, "PulseArrays", (PyObject *)&PulsesType) < 0
        || PyModule_AddObjectRef(m, "AuditRows", (PyObject *)&AuditType) < 0
        || PyModule_AddObjectRef(m, "BodiesReordered", BodiesReordered) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
