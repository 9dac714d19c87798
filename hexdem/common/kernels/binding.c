/* Binding C structs to Python arguments passed by name: see binding.h. */
#include "binding.h"

#include <stdio.h>
#include <string.h>

static const char *type_name(char kind)
{
    return kind == 'd' ? "float64" : "int64";
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

/* A buffer's item type as NumPy names it ("float32", "int64", "uint8"...), or its format. */
static const char *buffer_type(const Py_buffer *view)
{
    static char text[32];
    const char *format = view->format ? view->format : "B";
    if (*format == '@' || *format == '=' || *format == '<')
        format++;
    const char *kind = strchr("efd", *format) ? "float" : strchr("bhilqn", *format) ? "int"
                     : strchr("BHILQN", *format) ? "uint" : NULL;
    if (!kind || strlen(format) != 1)
        snprintf(text, sizeof text, "format '%.16s'", format);
    else
        snprintf(text, sizeof text, "%s%zd", kind, 8 * view->itemsize);
    return text;
}

static Py_ssize_t axis_length(const Axis *axis, const Py_ssize_t *sizes)
{
    return (axis->size == NO_SIZE ? 0 : axis->times * sizes[axis->size]) + axis->plus;
}

/* "(n, capacity) = (7, 12)" (sizes that are known) into text. */
static void describe_shape(const Table *table, const Field *field, const Py_ssize_t *sizes, char *text, size_t room)
{
    char symbols[96] = "", numbers[64] = "";
    for (int k = 0; k < field->ndim; k++) {
        const Axis *axis = &field->axes[k];
        char symbol[40], number[24];
        const char *rule = axis->rule == AT_LEAST ? ">= " : axis->rule == EMPTY_OR_AT_LEAST ? "0 or >= " : "";
        if (axis->size == NO_SIZE)
            snprintf(symbol, sizeof symbol, "%d", axis->plus);
        else if (axis->times != 1)
            snprintf(symbol, sizeof symbol, "%s%d %s", rule, axis->times, table->sizes[axis->size]);
        else
            snprintf(symbol, sizeof symbol, axis->plus ? "%s%s + %d" : "%s%s", rule, table->sizes[axis->size], axis->plus);
        if (axis->size != NO_SIZE && sizes[axis->size] < 0)
            snprintf(number, sizeof number, "?");
        else
            snprintf(number, sizeof number, "%zd", axis_length(axis, sizes));
        size_t used = strlen(symbols), used_numbers = strlen(numbers);
        snprintf(symbols + used, sizeof symbols - used, "%s%s", k ? ", " : "", symbol);
        snprintf(numbers + used_numbers, sizeof numbers - used_numbers, "%s%s", k ? ", " : "", number);
    }
    if (field->ndim == 1) {
        strncat(symbols, ",", sizeof symbols - strlen(symbols) - 1);
        strncat(numbers, ",", sizeof numbers - strlen(numbers) - 1);
    }
    snprintf(text, room, "(%s) = (%s)", symbols, numbers);
}

/* The array argument `field` from `value` into the buffer `view` (held on success), its data
 * into the struct at `target`, its axes checked against (or giving) the sizes. */
static int take_array(const Table *table, const Field *field, PyObject *value, Py_buffer *view, void *target,
                      Py_ssize_t *sizes)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (field->writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(value, view, flags) != 0) {
        PyErr_Format(PyExc_TypeError, "%s: %s: not a C-ordered%s array", table->kernel, field->name,
                     field->writable ? " writable" : "");
        return -1;
    }
    int fits = has_type(view, field->kind) && view->ndim == field->ndim;
    for (int k = 0; fits && k < field->ndim; k++) {
        const Axis *axis = &field->axes[k];
        Py_ssize_t length = view->shape[k];
        if (axis->size != NO_SIZE && sizes[axis->size] < 0) {
            sizes[axis->size] = length;
            continue;
        }
        Py_ssize_t wanted = axis_length(axis, sizes);
        fits = axis->rule == EXACT ? length == wanted
               : axis->rule == AT_LEAST ? length >= wanted
                                        : length == 0 || length >= wanted;
    }
    if (!fits) {
        char shape[160], got[64] = "";
        describe_shape(table, field, sizes, shape, sizeof shape);
        for (int k = 0; k < view->ndim && k < 4; k++) {
            size_t used = strlen(got);
            snprintf(got + used, sizeof got - used, "%s%zd", k ? ", " : "", view->shape[k]);
        }
        PyErr_Format(PyExc_TypeError, "%s: %s: expected %s %s, got %s (%s%s)", table->kernel, field->name,
                     type_name(field->kind), shape, buffer_type(view), got, view->ndim == 1 ? "," : "");
        PyBuffer_Release(view);
        return -1;
    }
    if (field->length_as != NO_SIZE)
        sizes[field->length_as] = view->shape[0];
    *(void **)((char *)target + field->offset) = view->buf;
    return 0;
}

static int take_scalar(const Table *table, const Field *field, PyObject *value, void *target)
{
    if (field->kind == 'i') {
        long long number = PyLong_AsLongLong(value);
        if (number == -1 && PyErr_Occurred()) {
            PyErr_Format(PyExc_TypeError, "%s: %s: expected an integer", table->kernel, field->name);
            return -1;
        }
        *(int64_t *)((char *)target + field->offset) = number;
        return 0;
    }
    double number = PyFloat_AsDouble(value);
    if (number == -1.0 && PyErr_Occurred()) {
        PyErr_Format(PyExc_TypeError, "%s: %s: expected a number", table->kernel, field->name);
        return -1;
    }
    *(double *)((char *)target + field->offset) = number;
    return 0;
}

void release_views(Py_buffer *views, int *held)
{
    for (int k = 0; k < *held; k++)
        PyBuffer_Release(&views[k]);
    *held = 0;
}

/* The index of the table's field called `name` (-1: none): by identity, as the call's keywords are
 * mostly the interned names (first the field at `hint`, a call's keywords mostly being in the
 * table's order), else by value. */
static int field_named(const Table *table, PyObject *name, Py_ssize_t hint)
{
    if (hint < table->n_fields && name == table->names[hint])
        return (int)hint;
    for (int f = 0; f < table->n_fields; f++)
        if (name == table->names[f])
            return f;
    for (int f = 0; f < table->n_fields; f++)
        if (PyUnicode_Compare(name, table->names[f]) == 0)
            return f;
    if (PyErr_Occurred())
        PyErr_Clear();
    return -1;
}

int bind_arguments(const Table *table, PyObject *const *args, Py_ssize_t nargs, PyObject *kwnames, void *target,
                   Py_buffer *views, int *held, Py_ssize_t *sizes)
{
    PyObject *values[MAX_FIELDS] = {NULL};
    Py_ssize_t n_given = kwnames ? PyTuple_GET_SIZE(kwnames) : 0;
    if (nargs) {
        PyErr_Format(PyExc_TypeError, "%s takes its arguments by name (%zd given by position)", table->kernel, nargs);
        return -1;
    }
    for (Py_ssize_t k = 0; k < n_given; k++) {
        int f = field_named(table, PyTuple_GET_ITEM(kwnames, k), k);
        if (f < 0) {
            PyErr_Format(PyExc_TypeError, "%s takes no argument named %R", table->kernel, PyTuple_GET_ITEM(kwnames, k));
            return -1;
        }
        values[f] = args[k];
    }
    *held = 0;
    for (int f = 0; f < table->n_fields; f++) {
        const Field *field = &table->fields[f];
        if (!values[f]) {
            PyErr_Format(PyExc_TypeError, "%s: missing argument %s", table->kernel, field->name);
            goto fail;
        }
        if (field->kind == 'd' || field->kind == 'q') {
            if (take_array(table, field, values[f], &views[*held], target, sizes) != 0)
                goto fail;
            (*held)++;
        } else if (take_scalar(table, field, values[f], target) != 0)
            goto fail;
    }
    return 0;
fail:
    release_views(views, held);
    return -1;
}

int intern_names(Table *table)
{
    table->names = PyMem_Calloc(table->n_fields, sizeof(PyObject *));
    if (!table->names) {
        PyErr_NoMemory();
        return -1;
    }
    for (int f = 0; f < table->n_fields; f++)
        if (!(table->names[f] = PyUnicode_InternFromString(table->fields[f].name)))
            return -1;
    return 0;
}

PyObject *index_error(const char *name)
{
    PyErr_Format(PyExc_IndexError, "%s: an index lies outside its array", name);
    return NULL;
}

void fresh_sizes(Py_ssize_t *sizes)
{
    for (int k = 0; k < MAX_SIZES; k++)
        sizes[k] = -1;
}

void bound_dealloc(PyObject *self)
{
    Bound *bound = (Bound *)self;
    release_views(bound->views, &bound->held);
    Py_TYPE(self)->tp_free(self);
}

PyObject *bound_new(PyTypeObject *type, PyObject *args, PyObject *kwargs, const Table *table, Py_ssize_t target_offset,
                    Py_ssize_t views_offset)
{
    if (PyTuple_GET_SIZE(args)) {
        PyErr_Format(PyExc_TypeError, "%s takes its arguments by name (%zd given by position)", table->kernel,
                     PyTuple_GET_SIZE(args));
        return NULL;
    }
    Py_ssize_t n = kwargs ? PyDict_GET_SIZE(kwargs) : 0;
    PyObject *names = PyTuple_New(n), **values = PyMem_Calloc(n ? n : 1, sizeof(PyObject *));
    PyObject *self = type->tp_alloc(type, 0);
    if (!names || !values || !self)
        goto fail;
    Py_ssize_t position = 0, k = 0;
    PyObject *key, *value;
    while (kwargs && PyDict_Next(kwargs, &position, &key, &value)) {
        Py_INCREF(key);
        PyTuple_SET_ITEM(names, k, key);
        values[k++] = value;
    }
    Bound *bound = (Bound *)self;
    bound->views = (Py_buffer *)((char *)self + views_offset);
    fresh_sizes(bound->sizes);
    if (bind_arguments(table, values, 0, names, (char *)self + target_offset, bound->views, &bound->held, bound->sizes) != 0)
        goto fail;
    Py_DECREF(names);
    PyMem_Free(values);
    return self;
fail:
    Py_XDECREF(names);
    PyMem_Free(values);
    Py_XDECREF(self);
    return NULL;
}

