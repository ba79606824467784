"""specrefine.experiments.aim_check: the per-leg loss by disc radius, its refusal of a folder with no run, and the
sentences README and docs/corrector.md quote from the shipped check (data/results/corrector/diagnosis/aim.json)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from specrefine.experiments import aim_check

ROOT = Path(__file__).resolve().parents[1]


def test_legs_are_binned_by_the_radius_of_the_disc_they_enter():
    bins = aim_check.radius_bins([(0.1, 0.004), (0.15, 0.002), (0.25, 0.001), (0.5, 0.0), (None, 0.5)])
    assert [b["legs"] for b in bins] == [2, 1, 0, 1]  # a leg into another region (None) is in no bin
    assert bins[0]["loss"] == pytest.approx(0.003) and bins[1]["loss"] == pytest.approx(0.001)
    assert math.isnan(bins[2]["loss"]) and bins[3]["loss"] == 0.0


def test_a_folder_without_such_runs_is_one_line_and_writes_nothing(tmp_path, capsys):
    out = tmp_path / "aim.md"
    with pytest.raises(SystemExit) as exc:
        aim_check.main([str(tmp_path), "--out", str(out)])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "no point-mass run folder" in err and err.count("\n") == 1
    assert not out.exists()


def test_a_json_beside_the_report_that_is_a_link_is_refused_before_any_work(tmp_path, capsys):
    (tmp_path / "target.json").write_text("keep")
    (tmp_path / "aim.json").symlink_to(tmp_path / "target.json")
    with pytest.raises(SystemExit) as exc:
        aim_check.main([str(tmp_path / "no_sweep"), "--out", str(tmp_path / "aim.md")])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "aim.json" in err and "no_sweep" not in err and err.count("\n") == 1
    assert (tmp_path / "target.json").read_text() == "keep" and not (tmp_path / "aim.md").exists()


def test_the_corrector_doc_quotes_the_shipped_check():
    check = json.loads((ROOT / "data/results/corrector/diagnosis/aim.json").read_text())
    lost, bins = check["lost"], check["bins"]
    (stop,) = {f"{d * 1000:.1f} mm" for d in check["stop_offset"]}  # the same rest offset at every point
    doc = " ".join((ROOT / "docs/corrector.md").read_text().split())
    moved, section = doc.split("The point mass's corrector, step by step (moved from README")[1], doc  # README's, once
    assert f"{lost['timeout']} of the {sum(lost.values())} episodes" in moved
    assert f"{lost['timeout']} of their {sum(lost.values())} lost episodes" in section
    for text in (moved, section):
        assert f"rest {stop} from the point it aims at" in text
        assert f"{bins[0]['loss'] * 100:.2f} %" in text and f"{bins[2]['loss'] * 100:.2f} %" in text
    assert f"by a median of {np.median(check['gaps']) * 1000:.1f} mm" in doc
