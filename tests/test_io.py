"""Result files are strict JSON and written atomically (hexdem.common.io)."""

import json

import numpy as np
import pytest

from hexdem.common.io import write_json


def test_json_results_are_strict_and_atomic(tmp_path):
    path = tmp_path / "r.json"
    write_json(path, {"a": float("nan"), "b": np.array([1.0, np.inf]), "c": np.float64(2.5)})
    assert json.loads(path.read_text(), parse_constant=lambda token: pytest.fail(token)) == {
        "a": None, "b": [1.0, None], "c": 2.5}
    with pytest.raises(TypeError, match="Object of type object is not JSON serializable"):
        write_json(path, {"a": object()})
    assert json.loads(path.read_text())["c"] == 2.5
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]
