"""The configuration a LAMMPS deck directory carries for ``hexdem analyse``: ``hexdem.json``,
and a copy of each input file it names, so that the deck stands alone.

:func:`write_deck_config` copies the files of :data:`FILE_KEYS` (a ``sites_file``, an
``initial_state_file``, a ``packing_file``) into the deck as ``<key><suffix>`` and names the copies in
``hexdem.json``; :func:`read_deck_config` reads such a name relative to the deck, so the deck
describes the same packing wherever it is moved and from wherever it is analysed. A
``hexdem.json`` that is not a table of run-config keys is refused in one line.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from hexdem.common.io import atomic_path, write_json
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig

#: The configuration of a LAMMPS deck, in its directory.
CONFIG_NAME = "hexdem.json"
#: The run-config keys that name input files, copied into the deck.
FILE_KEYS = ("sites_file", "initial_state_file", "packing_file")
#: The time step of decks written before ``steps_per_contact`` existed: τ/700.
LEGACY_STEPS_PER_CONTACT = 700


def write_deck_config(config: RunConfig, deck: Path) -> None:
    """Write ``config`` as ``deck/hexdem.json``, with a copy of each file it names beside it."""
    data = config.as_dict()
    for key in FILE_KEYS:
        if data[key] is not None:
            copy = f"{key}{Path(data[key]).suffix}"
            with atomic_path(deck / copy) as tmp:
                shutil.copyfile(data[key], tmp)
            data[key] = copy
    write_json(deck / CONFIG_NAME, data)


def read_deck_config(deck: Path) -> RunConfig:
    """The :class:`RunConfig` a ``hexdem run`` deck directory was written for."""
    path = deck / CONFIG_NAME
    try:
        data = json.loads(path.read_text())
    except OSError:
        raise HexdemError(f"{deck} has no {CONFIG_NAME}: it is not a deck directory written by hexdem run") from None
    except ValueError:
        raise HexdemError(f"{path} is not valid JSON") from None
    if not isinstance(data, dict):
        raise HexdemError(
            f"{path} holds {json.dumps(data)[:40]} where a table of run-config keys belongs: it is damaged"
        )
    data.setdefault("steps_per_contact", LEGACY_STEPS_PER_CONTACT)  # a deck written before the key existed
    for key in FILE_KEYS:
        if isinstance(data.get(key), str):
            data[key] = str(deck / data[key])  # a copy in the deck (an older deck's absolute path stays)
    return RunConfig.from_dict(data, source=str(path), given=False)  # every key written: only values set
