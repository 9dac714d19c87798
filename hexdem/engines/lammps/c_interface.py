"""The sampling path's calls into LAMMPS's C library interface: the per-atom arrays as NumPy views
kept from one sample to the next, and a ``fix external`` callback that builds no arrays.

The ``lammps`` module builds a new NumPy view of a per-atom array at each request (new ctypes
array types, ``np.frombuffer``), and its ``fix external`` callback builds three before it calls
Python: library and ctypes calls at every sample (their cost: docs/validation/benchmarks.md,
*Figures moved out of the docstrings*). LAMMPS moves a per-atom array only
when it grows it, so :class:`AtomViews` asks the C library interface for the array's address
(``lammps_extract_atom``, under a microsecond) and makes a view only when that address or the
atom count changed; :func:`add_sampling_fix` registers a callback that gets the step and the
atom count, and reads the arrays through those views.
"""

from __future__ import annotations

import ctypes

import numpy as np

#: ``lammps_extract_atom(handle, name)``: the address of a per-atom array (of its row pointers for
#: a two-axis one), with a result type of its own (the ``lammps`` module resets the shared one's).
_EXTRACT_ATOM = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p)
#: LAMMPS's ``FixExternalFnPtr``: (caller, timestep, nlocal, tag, x, fexternal), pointers as addresses.
_CALLBACK = ctypes.CFUNCTYPE(
    None, ctypes.py_object, ctypes.c_int64, ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p
)
_SET_CALLBACK = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p, _CALLBACK, ctypes.py_object)
#: ``lammps_get_thermo(handle, keyword)``: a thermo keyword's current value.
_GET_THERMO = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_void_p, ctypes.c_char_p)
#: The C ``tagint`` of LAMMPS's atom ids, by its size in bytes (``extract_setting("tagint")``).
_TAG_TYPES = {4: np.int32, 8: np.int64}


class AtomViews:
    """Views of the per-atom arrays of the LAMMPS instance ``lmp`` (a ``lammps.lammps``), valid until
    LAMMPS's next step: ``views("x", n, 3)``, ``views("rmass", n)``, ``views("id", n)``."""

    def __init__(self, lmp):
        self._handle = lmp.lmp
        self._extract = _EXTRACT_ATOM(("lammps_extract_atom", lmp.lib))
        self._tag_type = _TAG_TYPES[lmp.extract_setting("tagint")]
        self._kept: dict[tuple[str, int], tuple[int, int, np.ndarray]] = {}

    def __call__(self, name: str, n: int, columns: int = 0) -> np.ndarray:
        """The first ``n`` rows of per-atom array ``name``: (n, columns), or (n,) for ``columns = 0``;
        float64, or LAMMPS's integer type for the ids ("id")."""
        dtype = self._tag_type if name == "id" else np.float64
        address = self._extract(self._handle, name.encode())
        if columns and address:
            address = ctypes.c_void_p.from_address(address).value
        kept = self._kept.get((name, columns))
        if kept is None or kept[0] != address or kept[1] != n:
            kept = self._kept[(name, columns)] = (address, n, _view(address, n, columns, dtype))
        return kept[2]


def neighbour_builds(lmp):
    """A function of no argument giving the neighbour-list builds of ``lmp``'s current run so far
    (the thermo keyword ``nbuild``, read on this rank without communication)."""
    get_thermo, handle = _GET_THERMO(("lammps_get_thermo", lmp.lib)), lmp.lmp
    return lambda: get_thermo(handle, b"nbuild")


def _view(address: int | None, n: int, columns: int, dtype) -> np.ndarray:
    """A NumPy view of ``n`` rows of ``columns`` (0: a vector) values of ``dtype`` at ``address``."""
    shape = (n, columns) if columns else (n,)
    count = n * max(columns, 1)
    if not address or not count:
        return np.empty(shape, dtype)
    block = (ctypes.c_char * (count * np.dtype(dtype).itemsize)).from_address(address)
    return np.frombuffer(block, dtype, count).reshape(shape)


def add_sampling_fix(lmp, fix_id: str, every: int, n_steps: int, callback, command) -> None:
    """Add ``fix fix_id all external`` to ``lmp``, calling ``callback(step, nlocal)`` every ``every``
    steps of a run of ``n_steps``, through ``command`` (``lmp.command``, or a wrapper of it).

    The fix adds no force: LAMMPS leaves its force array unset, and adding it at every step cost a
    pass over the atoms, so the fix adds it only every ``n_steps + 1`` steps, that is at the
    set-up's step 0 alone, whose call sets it to zero (and calls nothing else). The C callback is kept
    on ``lmp``, as the ``lammps`` module keeps its own, so that it lives as long as the instance."""

    def raw(caller, step, nlocal, tag, x, fexternal):
        if step == 0:
            _view(ctypes.c_void_p.from_address(fexternal).value if fexternal else None, nlocal, 3, np.float64)[:] = 0.0
        else:
            callback(step, nlocal)

    command(f"fix {fix_id} all external pf/callback {every} {n_steps + 1}")
    function = _CALLBACK(raw)
    lmp.callback[fix_id] = {"function": function, "caller": None}
    _SET_CALLBACK(("lammps_set_fix_external_callback", lmp.lib))(lmp.lmp, fix_id.encode(), function, None)
