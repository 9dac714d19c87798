"""A packing listed site by site: the labels {m, n} of the paper's convention, inline or in a file.

``sites_file`` is a CSV with columns ``m,n`` (a header line, then one site per line) or a TOML
file with ``sites = [[m, n], …]``. The struck bead is {0, 0} (or the first impact's site); flat walls touch the packing
at
the inward-normal angles given (:func:`~hexdem.model.triangular.from_sites`), none by default.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from hexdem.common.io import read_text
from hexdem.errors import HexdemError
from hexdem.model.packing import Packing
from hexdem.model.placed import check_extent
from hexdem.model.triangular import from_sites


def _sites_from_file(path: Path) -> list:
    text = read_text(path, "sites_file")
    if path.suffix == ".toml":
        import tomllib  # here, as in hexdem.common.io.read_toml: the MPI ranks read no TOML

        try:
            sites = tomllib.loads(text).get("sites")
        except tomllib.TOMLDecodeError as exc:
            raise HexdemError(f"sites_file {path} is not valid TOML: {exc}") from None
        if not isinstance(sites, list):
            raise HexdemError(f"sites_file {path} has no list 'sites = [[m, n], ...]'")
        return sites
    rows = list(csv.reader(line for line in text.splitlines() if line.strip()))
    if not rows or [cell.strip() for cell in rows[0]] != ["m", "n"]:
        raise HexdemError(f"sites_file {path}: a CSV of sites starts with the header line 'm,n'")
    try:
        return [[int(m), int(n)] for m, n in rows[1:]]
    except ValueError:
        raise HexdemError(f"sites_file {path}: every line after the header must be two integers m,n") from None


def read_sites(sites, sites_file, diameter_m: float, walls_deg=(), struck=(0, 0)) -> Packing:
    """The packing of ``sites`` (pairs [m, n]) or of the sites in ``sites_file`` (exactly one of
    the two), with flat walls at the inward-normal angles ``walls_deg``, struck at ``struck``."""
    if bool(sites) == bool(sites_file):
        raise HexdemError('shape = "sites" needs exactly one of sites = [[m, n], ...] and sites_file')
    listed = _sites_from_file(Path(sites_file)) if sites_file else list(sites)
    if not all(isinstance(site, (list, tuple)) and len(site) == 2 for site in listed):
        raise HexdemError("sites must be pairs [m, n] of integers")
    try:
        angles = [float(a) for a in walls_deg]
    except (TypeError, ValueError):
        raise HexdemError(f"site_walls_deg must be a list of angles in degrees, got {walls_deg!r}") from None
    source = f"{len(listed)} sites of {sites_file}" if sites_file else f"{len(listed)} listed sites"
    try:
        labels = np.asarray(listed, dtype=float)
    except (TypeError, ValueError):
        labels = None  # from_sites words the error
    if labels is not None and len(labels) and diameter_m > 0:
        check_extent(
            labels[:, ::-1] * [math.sqrt(3) / 2 * diameter_m, diameter_m / 2],
            np.full(len(labels), float(diameter_m)),
            source,
        )
    return from_sites(listed, diameter_m, angles, source, struck)
