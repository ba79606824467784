"""Every roadmap chain search of one run, node by node, written as JSON (a diagnosis, docs/corrector.md, "Where the
held-out runs at 0 stall"); the run itself is ``specrefine refine`` with the same arguments:

    PYTHONPATH=. .venv/bin/python scripts/trace_roadmap.py OUT.json refine MAZE --method ours-corrector-sound ...

Per search: its origin and goal (region centres), the waypoints pooled, the dead legs remembered, each expansion's
candidates (x, y, success on that search's rollouts) and the chain it returned.
"""

import json
import os
import sys
import tempfile

import specrefine.refine.roadmap as roadmap
from specrefine.cli import main

SEARCHES: list[dict] = []
_evaluate_all, _chain = roadmap.evaluate_all, roadmap.Roadmap.chain


def _xy(region) -> list[float]:
    return [round(float(c), 2) for c in region.centre()]


def evaluate_all(evaluator, jobs):
    results = _evaluate_all(evaluator, jobs)
    SEARCHES[-1]["expansions"].append([_xy(goal) + [round(r.p, 3)] for (_, goal, _, _), r in zip(jobs, results)])
    return results


def chain(self, evaluator, start, origin, goal, avoid, goal_point=None):
    SEARCHES.append({"origin": _xy(origin), "goal": _xy(goal), "pooled": len(self.points), "dead": len(self.dead),
                     "expansions": []})
    found = _chain(self, evaluator, start, origin, goal, avoid, goal_point)
    SEARCHES[-1] |= {"chain": [_xy(r) for r in found.waypoints], "reaches_goal": bool(found.reaches_goal)}
    return found


if __name__ == "__main__":
    if len(sys.argv) < 3 or not os.path.isdir(os.path.dirname(os.path.abspath(sys.argv[1]))) \
            or os.path.isdir(sys.argv[1]):
        print("usage: trace_roadmap.py OUT.json refine MAZE ... (OUT.json a file in an existing folder)",
              file=sys.stderr)
        sys.exit(2)
    roadmap.evaluate_all, roadmap.Roadmap.chain = evaluate_all, chain
    out = sys.argv[1]
    try:
        main(sys.argv[2:])
    finally:  # written whole (temp + rename), also when the run fails midway
        fd, tmp = tempfile.mkstemp(dir=os.path.dirname(os.path.abspath(out)), suffix=".tmp")
        with os.fdopen(fd, "w") as f:
            json.dump(SEARCHES, f)
        os.chmod(tmp, 0o644)  # mkstemp's 0600 would keep a shipped table from other readers
        os.replace(tmp, out)
