"""Atomic output: a result file is either complete or absent, never half-written."""

from __future__ import annotations

import csv
import fcntl
import json
import math
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from hexdem.common.interrupt import deferred_signals
from hexdem.errors import HexdemError


@contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; move it onto ``path`` only if the block succeeds."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part")
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


@contextmanager
def file_lock(path, holder: str | None = None):
    """Hold an exclusive lock on the file ``path`` (made if needed) for the block; yields its
    descriptor (MPI launchers started inside inherit it, so the lock lasts as long as they do).
    A lock held elsewhere is waited for, or, given the ``holder`` that may hold it, refused in one
    line naming the folder."""
    fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | (fcntl.LOCK_NB if holder else 0))
        except BlockingIOError:
            raise HexdemError(
                f"{Path(path).parent} is in use by {holder}; wait for it or choose another --out"
            ) from None
        yield fd
    finally:
        os.close(fd)


def locked_directory(out: Path, holder: str):
    """Hold ``out/.lock`` so that two runs never share ``out`` (:func:`file_lock`); ``holder``
    names who else may hold it, for the refusal."""
    return file_lock(Path(out) / ".lock", holder)


@contextmanager
def atomic_directory(folder):
    """Yield the path ``.NAME.part`` beside ``folder`` (removed first, not made) to build the folder
    in; rename it onto ``folder`` when the block succeeds, remove it when it fails: a folder that
    exists is complete, and a stop during the rename is raised after it."""
    folder = Path(folder)
    partial = folder.with_name(f".{folder.name}.part")
    shutil.rmtree(partial, ignore_errors=True)
    try:
        yield partial
        with deferred_signals():
            os.replace(partial, folder)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise


def read_text(path, what: str) -> str:
    """The text of the UTF-8 file at ``path``, without the byte-order mark some editors write
    first; an unreadable file, or one that is not UTF-8 text, is one clear line naming it as ``what``."""
    try:
        return Path(path).read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise HexdemError(f"cannot read {what} {path}: {exc.strerror}") from None
    except UnicodeDecodeError as exc:
        raise HexdemError(
            f"{what} {path} is not UTF-8 text (byte {exc.start}: {exc.object[exc.start : exc.start + 1]!r})"
        ) from None


def read_toml(path, what: str = "config") -> dict:
    """The table of the TOML file at ``path``; an unreadable or invalid file is one clear line
    naming it as ``what``."""
    import tomllib  # here: the MPI ranks and workers, which read no TOML, do not load it

    path = Path(path)
    try:
        return tomllib.loads(read_text(path, what))
    except tomllib.TOMLDecodeError as exc:
        raise HexdemError(f"{what} {path} is not valid TOML: {exc}") from None


def write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def _strict_json(value):
    """``value`` with NaN and ±inf as null and NumPy scalars and arrays as Python values."""
    if isinstance(value, dict):
        return {key: _strict_json(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_strict_json(item) for item in value]
    if hasattr(value, "tolist"):
        return _strict_json(value.tolist())
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def write_json(path, data) -> None:
    """Write strict JSON (no NaN/Infinity tokens, which many readers reject): non-finite → null."""
    write_text(path, json.dumps(_strict_json(data), indent=2, allow_nan=False) + "\n")


def write_csv(path, header, rows) -> None:
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        writer.writerows(rows)


def text_columns(columns) -> list[list[str]]:
    """Each of ``columns`` (NumPy arrays or lists of numbers or names) as text, a column at a time,
    as the csv module writes a value: a float by ``repr`` (the shortest text that reads back as the
    same number), anything else by ``str``. Each distinct value is written once
    (:func:`_column_text`)."""
    return [_column_text(np.asarray(column)) for column in columns]


def _column_text(column: np.ndarray) -> list[str]:
    """``column`` as text (see :func:`text_columns`), each distinct value converted once: a packing's
    columns hold few (its rows' coordinates, the zeros of the beads that never moved), so a column takes
    a fraction of the time of a conversion value by value (docs/validation/benchmarks.md, *The analysis at the
    engine's speed*). Floats are told apart by their bits (0.0 and
    −0.0 are written apart, as ``repr`` writes them)."""
    if column.dtype.kind == "O":
        return list(map(str, column.tolist()))
    floats = column.dtype.kind == "f"
    keys = np.ascontiguousarray(column, np.float64).view(np.int64) if floats else column
    distinct, inverse = np.unique(keys, return_inverse=True)
    values = distinct.view(np.float64) if floats else distinct
    words = np.array(list(map(repr if floats else str, values.tolist())), dtype=object)
    return words[inverse.reshape(-1)].tolist()


def write_csv_columns(path, header, columns) -> None:
    """The CSV :func:`write_csv` writes for the rows of ``columns`` (one sequence per name of
    ``header``, :func:`text_columns`), written a column at a time: a million rows of twelve
    columns in seconds, where a row writer takes half a minute."""
    texts = text_columns(columns)
    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        fh.write(",".join(header) + "\r\n")
        fh.writelines(",".join(row) + "\r\n" for row in zip(*texts))


@contextmanager
def staged_directory(out, prefix: str = ".hexdem-staging-"):
    """Yield a fresh hidden folder inside ``out`` (created if needed) to write results into. When
    the block succeeds, its entries move into ``out``, each replacing an older one of its name; when
    it fails, the folder is removed, and so is ``out`` if this created it and it is empty: a failed
    run leaves nothing in ``out``. A stop (SIGTERM, SIGINT) during the moves is raised after the
    last (:mod:`hexdem.common.interrupt`): the result is published whole or not at all."""
    out = Path(out)
    created = not out.exists()
    out = ensure_writable_dir(out)
    staging = Path(tempfile.mkdtemp(dir=out, prefix=prefix))
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        if created and not any(out.iterdir()):
            out.rmdir()
        raise
    with deferred_signals():  # a stop waits for the last move: no half of a result is published
        for entry in sorted(staging.iterdir()):
            target = out / entry.name
            if target.is_dir() and not target.is_symlink():
                shutil.rmtree(target)
            entry.replace(target)
        staging.rmdir()


def ensure_writable_dir(directory) -> Path:
    """Create ``directory`` if needed and prove we can write into it, or raise HexdemError."""
    directory = Path(directory)
    try:
        directory.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=directory, prefix=".hexdem-probe-"):
            pass
    except OSError as exc:
        raise HexdemError(f"output directory {directory} is not writable: {exc.strerror}") from None
    return directory


def keep_plan(path, plan: dict, study: str) -> None:
    """Write a study's ``plan`` (JSON) to ``path`` in its folder, or, where the folder holds one
    already, refuse another in one line: a rerun of the same command resumes the ``study``
    ("sweep", "calibration"), and one with another plan would mix two studies."""
    path = Path(path)
    out = path.parent
    if path.exists():
        try:
            previous = json.loads(path.read_text())
        except (OSError, ValueError):
            raise HexdemError(
                f"{path} is unreadable: {out} does not hold a hexdem {study}; choose another --out"
            ) from None
        if previous != json.loads(json.dumps(plan)):
            raise HexdemError(
                f"{out} holds a {study} with another plan; rerun the same command to resume it, or choose another --out"
            )
    write_json(path, plan)
