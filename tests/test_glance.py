"""glance.png: the default correctors per U-chain beside the oracle, ours and the one-shot, from the shipped tables."""

from __future__ import annotations

import csv

from specrefine.core.runfolder import save_figure
from specrefine.experiments.corrector_claims.glance import glance_figure, glance_panels, legend_labels
from specrefine.experiments.grids import ROOT, SCALING_MAZES


def _done(path, method, proposer):
    rows = [r for r in csv.DictReader((ROOT / path).open()) if r["method"] == method and r["proposer"] == proposer]
    return [r for r in rows if r["status"] == "ok"]


def test_each_curve_counts_the_episodes_of_its_tables_runs(tmp_path):
    panels = glance_panels()
    assert [p["title"] for p in panels] == ["point mass, imperfect:mild", "point mass, imperfect:moderate",
                                            "Ant, imperfect:moderate"]
    ant = {c["role"]: c for c in panels[2]["curves"]}
    span = _done("data/results/corrector/ant_span.csv", "ours-corrector-span", "imperfect:moderate")
    assert sum(runs for _, _, runs in ant["span"]["counts"]) == len(span)  # the cells run so far, no more
    for maze, (k, n, runs) in zip(SCALING_MAZES, ant["span"]["counts"]):
        here = [r for r in span if r["maze"] == maze]
        assert runs == len(here) and n == sum(int(r["episodes"]) for r in here)
        assert k == sum(round(float(r["success_rate"]) * int(r["episodes"])) for r in here)
    point = {c["role"]: c for c in panels[1]["curves"]}
    assert all(runs == 4 and n == 800 for _, n, runs in point["corrector"]["counts"])  # seeds 0-3, 200 episodes
    assert panels[2]["floor"] == 0.85 and panels[0]["floor"] is None
    labels = legend_labels(panels)
    assert labels["corrector"] == ("point mass: ours-corrector-span-bridge (default); "
                                   "Ant: ours-corrector-redraw (the default's run: its rescue never fires here)")
    assert labels["span"].startswith("Ant: ours-corrector-span") and labels["ours"] == "ours (the paper's search)"
    # the Ant's oracle at its correctors' settings (a confirmed pick), every cell run
    assert labels["oracle"] == ("point mass: oracle (ours, geometric planner); "
                                "Ant: oracle (ours-confirm, geometric planner)")
    assert sum(runs for _, _, runs in ant["oracle"]["counts"]) == 27
    save_figure(glance_figure(panels), tmp_path / "glance.png", dpi=40)
    assert (tmp_path / "glance.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
