"""Result files are strict JSON and written atomically (hexdem.common.io)."""

import csv
import json

import numpy as np
import pytest

from hexdem.common.io import write_csv, write_csv_columns, write_json


def test_json_results_are_strict_and_atomic(tmp_path):
    path = tmp_path / "r.json"
    write_json(path, {"a": float("nan"), "b": np.array([1.0, np.inf]), "c": np.float64(2.5)})
    assert json.loads(path.read_text(), parse_constant=lambda token: pytest.fail(token)) == {
        "a": None,
        "b": [1.0, None],
        "c": 2.5,
    }
    with pytest.raises(TypeError, match="Object of type object is not JSON serializable"):
        write_json(path, {"a": object()})
    assert json.loads(path.read_text())["c"] == 2.5
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]


def test_the_column_writer_writes_what_the_row_writer_writes(tmp_path):
    """Each distinct value is converted once, told apart by its bits: −0.0 stays −0.0, NaN, ±inf,
    the shortest round-trip text of every float, integers and names as ``str``."""
    rng = np.random.default_rng(3)
    floats = np.concatenate([[0.0, -0.0, np.nan, np.inf, -np.inf, 0.1, 1e-300, 5e-324], rng.normal(size=40)])
    floats = rng.choice(floats, 200)
    columns = [
        np.arange(200),
        rng.integers(-3, 3, 200),
        floats,
        rng.choice(["steel", "brass"], 200),
        floats.astype(np.float32),
    ]
    header = ["id", "n", "x", "material", "single"]
    write_csv_columns(tmp_path / "columns.csv", header, columns)
    write_csv(tmp_path / "rows.csv", header, zip(*[np.asarray(c).tolist() for c in columns]))
    assert (tmp_path / "columns.csv").read_bytes() == (tmp_path / "rows.csv").read_bytes()
    with open(tmp_path / "columns.csv", newline="") as fh:
        assert [row["x"] for row in csv.DictReader(fh)] == [repr(v) for v in floats.tolist()]
