"""specrefine.record / read_records / compare: the regression values of the notebooks."""

import nbformat
import numpy as np
from nbformat.v4 import new_code_cell, new_notebook, new_output

from specrefine.runs.notebook import MIME, _jsonable, compare, for_readers, read_records


def _nb(*payloads):
    outs = [new_output("display_data", data={MIME: p, "text/plain": p["name"]}, metadata={MIME: {"package": "x"}})
            for p in payloads]
    cell = new_code_cell("record(...)")
    cell.outputs = outs
    return new_notebook(cells=[cell])


def test_read_back_and_compare():
    nb = _nb({"name": "path", "value": ["S", "x0", "G"], "tol": None, "rel": None},
             {"name": "p", "value": 0.875, "tol": 0.125, "rel": None})
    rec = read_records(nbformat.from_dict(nb))
    assert rec["path"]["value"] == ["S", "x0", "G"] and rec["p"]["tol"] == 0.125 and rec["p"]["package"] == "x"
    expected = {"path": {"value": ["S", "x0", "G"]}, "p": {"value": 1.0, "tol": 0.125}}
    assert compare(rec, expected) == []
    moved = compare(rec, {"path": {"value": ["S", "G"]}, "p": {"value": 0.5, "tol": 0.125}, "n": {"value": 3}})
    assert any("'n'" in m and "did not record" in m for m in moved)
    assert any(m.startswith("figure path (length 3, expected 2)") for m in moved)
    assert any(m.startswith("figure p = 0.875, expected 0.5 within 0.125") for m in moved)


def test_exact_unless_a_tolerance_is_given():
    rec = {"n": {"value": 19}, "d": {"value": {"a": 0.5, "b": 1.0}}, "flag": {"value": True}}
    assert compare(rec, {"n": {"value": 18}, "d": {"value": {"a": 0.5, "b": 1.0}}, "flag": {"value": True}}) == [
        "figure n = 19, expected 18 exactly"]
    assert compare(rec, {"n": {"value": 18, "rel": 0.1}, "d": {"value": {"a": 0.6, "b": 1.0}, "tol": 0.2},
                         "flag": {"value": 1}}) == ["figure flag = True, expected 1 exactly"]


def test_jsonable_numpy_and_tuples():
    assert _jsonable({"a": np.float32(0.5), "b": (np.int64(2), np.arange(2))}) == {"a": 0.5, "b": [2, [0, 1]]}


def test_readers_copy_keeps_values_not_the_machine():
    """An executed copy for readers keeps every recorded value and drops the package path (a local path) and
    papermill's timestamps."""
    nb = nbformat.from_dict(_nb({"name": "p", "value": 0.875, "tol": 0.125, "rel": None}))
    nb.metadata["papermill"] = {"start_time": "t"}
    nb.cells[0].metadata["papermill"] = {"duration": 1.0}
    for_readers(nb)
    rec = read_records(nb)
    assert rec["p"]["value"] == 0.875 and rec["p"]["package"] is None
    assert "papermill" not in nb.metadata and "papermill" not in nb.cells[0].metadata
    assert MIME not in nb.cells[0].outputs[0].metadata  # the package path was all it held
