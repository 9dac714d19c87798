/* Binding C structs to Python arguments passed by name (module.c's kernels): each kernel's
 * arguments are a table of fields (name, type, shape, where in the kernel's struct), read field by
 * field; an array of another type, order or shape, a missing or unknown name, or an argument given
 * by position is a TypeError naming the argument and what it should be. */
#ifndef HEXDEM_BINDING_H
#define HEXDEM_BINDING_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <stddef.h>

/* How an axis's length is checked against a size: exactly, at least, or either 0 or at least. */
enum { EXACT, AT_LEAST, EMPTY_OR_AT_LEAST };

/* An axis of length times * size + plus (size: an index into the kernel's sizes; NO_SIZE: plus
 * alone). The first array whose axis names a size not yet known gives it (times 1, plus 0). */
#define NO_SIZE -1
typedef struct {
    int size, times, plus, rule;
} Axis;

#define SIZE(size) {size, 1, 0, EXACT}
#define SIZE_AT_LEAST(size) {size, 1, 0, AT_LEAST}
#define FIXED(k) {NO_SIZE, 0, k, EXACT}

/* A named argument: 'd' a float64 array, 'q' an int64 array, 'f' a float, 'i' an integer; its axes,
 * whether the kernel writes it, where in the kernel's struct its data (or value) goes, and the size
 * its first axis's length is kept as (NO_SIZE: none). */
typedef struct {
    const char *name;
    char kind;
    int ndim;
    Axis axes[2];
    int writable;
    Py_ssize_t offset;
    int length_as;
} Field;

typedef struct {
    const char *kernel;       /* for messages */
    const Field *fields;
    int n_fields;
    const char *const *sizes; /* the sizes' names, for messages */
    PyObject **names;         /* the fields' names, interned at import */
} Table;

/* A field's axes come last, as each may hold commas: ARRAY(name, kind, struct, member, axis). */
#define ARRAY(name, kind, type, member, ...) {name, kind, 1, {__VA_ARGS__, FIXED(0)}, 0, offsetof(type, member), NO_SIZE}
#define ARRAY2(name, kind, type, member, ...) {name, kind, 2, {__VA_ARGS__}, 0, offsetof(type, member), NO_SIZE}
#define OUT(name, kind, type, member, ...) {name, kind, 1, {__VA_ARGS__, FIXED(0)}, 1, offsetof(type, member), NO_SIZE}
#define OUT2(name, kind, type, member, ...) {name, kind, 2, {__VA_ARGS__}, 1, offsetof(type, member), NO_SIZE}
#define SCALAR(name, kind, type, member) {name, kind, 0, {FIXED(0), FIXED(0)}, 0, offsetof(type, member), NO_SIZE}
#define COUNT(fields) ((int)(sizeof(fields) / sizeof((fields)[0])))
#define MAX_SIZES 16
#define MAX_FIELDS 32
/* A table's fields fit bind_arguments's room for them. */
#define CHECKED(fields) _Static_assert(COUNT(fields) <= MAX_FIELDS, #fields ": more than MAX_FIELDS")


/* The table's arguments, passed by name only, into the struct at `target`: each array's buffer
 * into views (room for table->n_fields; *held counts those taken, released on failure), the sizes
 * its shapes give into sizes (-1: not yet known). */
int bind_arguments(const Table *table, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames, void *target,
         Py_buffer *views, int *held, Py_ssize_t *sizes);
void release_views(Py_buffer *views, int *held);
/* Every size not yet known. */
void fresh_sizes(Py_ssize_t *sizes);
/* The table's fields' names, interned (as Python interns a call's keywords), so that a name is
 * mostly found by identity; 0, or -1 with an exception. */
int intern_names(Table *table);
PyObject *index_error(const char *name);

/* A bound object: arguments bound once, whose buffers it holds for its life (its views lie in its
 * own struct, after its kernel's struct). */

typedef struct {
    PyObject_HEAD
    Py_buffer *views; /* the object's own, after its struct */
    int held;
    Py_ssize_t sizes[MAX_SIZES];
} Bound;

void bound_dealloc(PyObject *self);
/* A new bound object of `type`, its arguments (keywords only) bound by `table` into the kernel's
 * struct at target_offset in it, their buffers into its views at views_offset. */
PyObject *bound_new(PyTypeObject *type, PyObject *args, PyObject *kwargs, const Table *table, Py_ssize_t target_offset,
                    Py_ssize_t views_offset);

#endif
