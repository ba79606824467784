"""A calibrated prediction of the output policy's success, with a 95 % interval.

The search keeps the candidates that looked best, so the product of its own estimates along the
chosen path is biased upward (the winner's curse).  ``predict`` runs the chosen path's compositional
policy end to end on ``HOLDOUT_EPISODES`` HELD-OUT episodes (a seed neither the search nor the
measurement uses, started from the original initial set as the measurement is), puts a Jeffreys
Beta(k + 1/2, m - k + 1/2) posterior on its success probability, and reports the posterior mean
with two 95 % intervals: ``p_ci`` for the probability itself, and ``ci`` for what the run then
measures, the success rate over ``episodes`` fresh episodes (the posterior predictive: each draw
passed through a binomial of ``episodes``), the interval the measured ``success_rate`` should fall in.

Why end to end, not leg by leg: the first version re-estimated each leg on 32 held-out rollouts and
multiplied Jeffreys posteriors.  Each leg seen at 32/32 is then charged 1.5 % (posterior mean
32.5/33), so a 19-leg path that never fails (measured 0.990) was predicted 0.748 [0.585, 0.880], and
the interval held the measured success in only 113 of 135 comparison runs (84 %); that failure
informed this design (those runs are not a held-out test of it).  ``product_posterior`` is that
product for any number of independent legs; here it is used with one, the whole path.

The held-out episodes run on a copy of the evaluator, so the run's own counters (``evaluations``,
``sim_steps``) are those of the search and the measurement; ``prediction_sim_steps`` is their cost.
"""

from __future__ import annotations

import os
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.paper import PAPER

HOLDOUT_SEED_OFFSET = 2_000_029  # neither the search's seed nor the measurement's
HOLDOUT_EPISODES = 64  # end-to-end episodes behind a prediction
DRAWS = 20_000


@dataclass
class Prediction:
    p: float  # posterior mean of the path's success
    ci: tuple[float, float]  # 95 % predictive interval of the success rate measured over `episodes` episodes
    p_ci: tuple[float, float]  # 95 % credible interval of the path's success probability
    successes: int  # held-out episodes that succeeded
    holdout_episodes: int
    sim_steps: int  # simulated for the held-out episodes

    def to_dict(self) -> dict:
        return {"predicted_success": self.p, "predicted_ci": list(self.ci), "predicted_p_ci": list(self.p_ci),
                "prediction_successes": self.successes, "prediction_episodes": self.holdout_episodes,
                "prediction_sim_steps": self.sim_steps}


def product_posterior(successes, rollouts, seed: int = 0, draws: int = DRAWS,
                      episodes: int | None = None) -> tuple[float, tuple[float, float]]:
    """Posterior mean and 95 % interval of a product of independent success probabilities (Jeffreys prior);
    with ``episodes``, the interval is the posterior predictive one of a success rate over that many episodes."""
    s, n = np.asarray(successes, dtype=float), np.asarray(rollouts, dtype=float)
    if not len(s):
        return 0.0, (0.0, 0.0)
    a, b = s + 0.5, n - s + 0.5
    rng = np.random.default_rng(seed)
    samples = rng.beta(a, b, size=(draws, len(a))).prod(axis=1)
    if episodes:
        samples = rng.binomial(int(episodes), samples) / int(episodes)
    lo, hi = np.quantile(samples, [0.025, 0.975])
    return float(np.prod(a / (a + b))), (float(lo), float(hi))


def predict(evaluator, original, graph, path, seed: int = 0, episodes: int = PAPER.episodes,
            holdout_episodes: int = HOLDOUT_EPISODES) -> Prediction:
    """Held-out end-to-end estimate of the compositional policy along ``path`` of ``graph``, judged as the
    measurement judges it (on the ``original`` task graph, from its initial set)."""
    from ..evaluation.monitor import measure

    if not path or len(path) < 2:
        return Prediction(0.0, (0.0, 0.0), (0.0, 0.0), 0, 0, 0)
    holdout = evaluator.fresh_copy()
    held = measure(holdout, original, graph, path, holdout_episodes, seed + HOLDOUT_SEED_OFFSET)
    k, m = int(held.success.sum()), len(held.success)
    p, p_ci = product_posterior([k], [m], seed=seed)
    _, ci = product_posterior([k], [m], seed=seed, episodes=episodes)
    return Prediction(p, ci, p_ci, k, m, int(holdout.sim_steps))


def coverage(rows) -> tuple[int, int]:
    """(runs whose measured success lies inside predicted_ci, runs with a predicted_ci)."""
    inside = total = 0
    for r in rows:
        lo, hi = r.get("predicted_ci_low"), r.get("predicted_ci_high")
        if lo in (None, "") or hi in (None, ""):
            continue
        total += 1
        inside += float(lo) <= float(r["success_rate"]) <= float(hi)
    return inside, total


def result_file(run) -> Path:
    """The result.json of ``run``: a run folder, or a result file itself (shipped runs keep only that)."""
    run = Path(run)
    return run if run.is_file() else run / "result.json"


def run_name(run) -> str:
    """A run's name in a predictions table: the folder's name, or the result file's stem."""
    run = Path(run)
    return run.stem if run.is_file() else run.name


def predict_run(run, maze_dir=None) -> dict:
    """The prediction of an existing run (a folder with result.json and run.json, or a result.json file),
    made again with this module.

    For runs made before the prediction changed: the chosen graph and path are read back, a fresh
    evaluator (shipped policy, the run's agent, rollouts and seed) runs the held-out episodes.  A bare
    result file is taken to come from the shipped policy and the maze's own task (no run.json to say otherwise).
    ``maze_dir``: where to find a maze the result names by its stem when it is not in ``data/mazes/``
    (e.g. ``data/mazes/unseen``).
    """
    from .experiment import setup

    path, data, args, maze = checked_run(run, maze_dir)
    exp = setup(maze, agent=data["agent"], seed=int(data["seed"]),
                rollouts=int(data["rollouts_per_evaluation"]), spec=args.get("spec"))
    graph, original = data["graph"], data["input_graph"]
    prediction = predict(exp.evaluator, original, graph, data["path"], int(data["seed"]), int(data["episodes"]))
    return {"success_rate": data["success_rate"], **prediction.to_dict()}


#: What makes two rows the same run, and what a table without the column ran with: tables older than a column ran
#: the maze's own task, the paper's fixed protocol (the only one before ``evaluation`` existed), 32 rollouts,
#: 200 episodes and the shipped policy (the defaults of ``specrefine.runs.sweep`` and ``specrefine.bench``). The policy
#: is named by its fingerprint where the row has one, else by the ``policy`` column.
RUN_IDENTITY = {"maze": None, "agent": None, "method": None, "proposer": None, "seed": None, "spec": "",
                "evaluation": "fixed", "rollouts_per_evaluation": "32", "episodes": "200", "policy": "shipped"}


def run_identity(row: dict, table="") -> tuple:
    """The run a table row reports (``RUN_IDENTITY``); a row without a ``maze`` (a predictions table naming its run
    only by ``cell``) is its own run, by table and cell."""
    if not row.get("maze"):
        return ("cell", str(table), row.get("cell"))
    ident = [_canonical(row.get(k)) or default for k, default in RUN_IDENTITY.items() if k != "policy"]
    return (*ident, row.get("policy_fingerprint") or row.get("policy") or "shipped")


def _canonical(value) -> str:
    """'32', '32.0' and 32 alike (csv text or typed)."""
    text = "" if value is None else str(value)
    try:
        number = float(text)
    except ValueError:
        return text
    return str(int(number)) if number.is_integer() else text


def _above_zero(rows) -> list[dict]:
    return [r for r in rows if float(r["success_rate"]) > 0]


NEEDED = ("success_rate", "seed", "rollouts_per_evaluation", "episodes", "path", "graph", "input_graph")


def checked_run(run, maze_dir=None):
    """(result file, its data with the graphs built, run.json's arguments, the maze) of a finished run, checked
    before any simulation: anything unusable is a one-line :class:`~specrefine.core.errors.SpecrefineError`."""

    from ..core.errors import SpecrefineError
    from ..core.graph import TaskGraph
    from ..core.mazes import load_maze
    from ..core.records import read_json
    from ..core.runfolder import read_result, recorded_maze

    path = result_file(run)
    data = read_result(path)
    missing = [key for key in NEEDED if key not in data]
    if missing:
        raise SpecrefineError(f"{path}: result.json lacks {', '.join(missing)}")
    run_json = path.with_name("run.json") if path.name == "result.json" else None
    args = read_json(run_json, "run record") if run_json and run_json.is_file() else {}
    if not isinstance(args, dict):
        raise SpecrefineError(f"{run_json}: unreadable run record")
    if args.get("policy", "shipped") != "shipped":
        raise SpecrefineError(f"{path}: made with policy {args['policy']!r}; only shipped-policy runs are redone")
    maze = recorded_maze(path, data["maze"], maze_dir)
    try:
        data = {**data, "graph": TaskGraph.from_dict(data["graph"]),
                "input_graph": TaskGraph.from_dict(data["input_graph"])}
        int(data["seed"]), int(data["rollouts_per_evaluation"]), int(data["episodes"]), float(data["success_rate"])
    except (KeyError, TypeError, ValueError, AttributeError) as exc:
        raise SpecrefineError(f"{path}: a malformed result.json ({type(exc).__name__}: {exc})") from None
    return path, data, args, maze if not isinstance(maze, (str, Path)) else load_maze(maze)


def table_rows(table) -> list[dict]:
    """The rows of a predictions table (any CSV with success_rate and predicted_ci_low/high) that have an interval;
    a table that does not parse, or holds no such row, is a one-line
    :class:`~specrefine.core.errors.SpecrefineError`."""
    from ..core.errors import SpecrefineError
    from ..core.tables import read_checked_table

    rows = [r for r in read_checked_table(table) if r.get("predicted_ci_low") not in (None, "")
            and r.get("predicted_ci_high") not in (None, "")]
    if not rows:
        raise SpecrefineError(f"{table}: no row with success_rate and predicted_ci_low/high: not a predictions table")
    try:
        coverage(rows)
    except (KeyError, TypeError, ValueError) as exc:
        raise SpecrefineError(f"{table}: a row without a numeric success_rate or predicted_ci ({exc})") from None
    return rows


def table_coverage(table) -> tuple[int, int]:
    """``coverage`` of a predictions table (``table_rows``)."""
    return coverage(table_rows(table))


def coverage_report(tables) -> str:
    """One line per predictions table (its rows, and those measured above 0: success 0 predicted near 0 is covered
    trivially), then, over all tables, the distinct runs (``run_identity``; a run in two rows or tables counts once,
    its first row) and how many rows that dropped."""
    lines, distinct, by_cell = [], {}, 0
    for table in tables:
        rows = table_rows(table)
        lines.append(f"{table}: {_covered(*coverage(rows))}; above 0: {_covered(*coverage(_above_zero(rows)), False)}")
        for r in rows:
            ident = run_identity(r, table)
            by_cell += ident[0] == "cell"
            distinct.setdefault(ident, r)
    if len(lines) > 1:
        runs = list(distinct.values())
        dropped = sum(len(table_rows(t)) for t in tables) - len(runs)
        lines.append(f"all, distinct runs: {_covered(*coverage(runs))}; above 0: "
                     f"{_covered(*coverage(_above_zero(runs)), False)}; {dropped} duplicate rows dropped (same "
                     f"{', '.join(RUN_IDENTITY)}); {by_cell} rows name their run by cell only (each counted as a run)")
    return "\n".join(lines)


def _covered(inside: int, total: int, words: bool = True) -> str:
    share = f"{inside}/{total}"
    return f"{share} measured success rates inside predicted_ci ({inside / max(total, 1):.1%})" if words else \
        f"{share} ({inside / max(total, 1):.1%})"


def _done_cells(table) -> set[str]:
    """The cells ``table`` has rows for; none where it is no regular file (a link, a FIFO: refused when appended)."""
    import csv

    if table.is_symlink() or not table.is_file():
        return set()
    with table.open(newline="") as fh:
        return {r["cell"] for r in csv.DictReader(fh)}


def _predict_into(table, runs, maze_dir=None) -> int:
    """Append one row per run not yet in ``table`` (resumable, flushed row by row); the number of runs that
    failed (each named on one line; the others go on)."""
    import csv

    from tqdm.auto import tqdm

    from ..core.errors import SpecrefineError
    from ..core.runfolder import appending_alone

    fields = ["cell", "success_rate", "predicted_success", "predicted_ci_low", "predicted_ci_high",
              "prediction_successes", "prediction_episodes", "prediction_sim_steps"]
    missing = [r for r in runs if not result_file(r).exists()]
    if missing:  # e.g. the folders of failed sweep cells in a glob
        print(f"skipped {len(missing)} run(s) without a result.json, e.g. {missing[0]}")
    runs = [r for r in runs if r not in missing]
    done = _done_cells(table)
    for run in [r for r in runs if run_name(r) not in done]:  # every run checked before any is simulated: a bad
        try:  # one is one line, exit 2
            checked_run(run, maze_dir)
        except SpecrefineError as exc:
            raise SpecrefineError(f"{run}: {exc}" if not str(exc).startswith(str(run)) else str(exc)) from None
    with appending_alone(table, "table") as fh:  # never through a link; a second calibrate here is refused
        done = _done_cells(table)  # what was appended before the table was ours
        todo = [r for r in runs if run_name(r) not in done]
        writer = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        if os.fstat(fh.fileno()).st_size == 0:
            writer.writeheader()
        failed = 0
        for run in tqdm(todo, desc="predictions"):
            try:
                d = predict_run(run, maze_dir)
            except (SpecrefineError, OSError) as exc:
                failed += 1
                print(f"{run}: {exc}", file=sys.stderr)
                continue
            writer.writerow({"cell": run_name(run), **d, "predicted_ci_low": d["predicted_ci"][0],
                             "predicted_ci_high": d["predicted_ci"][1]})
            fh.flush()
    return failed


def add_arguments(ap) -> None:
    """``specrefine calibrate RUN... --table OUT.csv``: predictions made again, and coverage;
    ``specrefine calibrate --coverage TABLE...``: the coverage of existing tables."""
    from ..core.argtypes import out_path

    ap.description = "Predictions made again, and their coverage (--coverage: of existing tables)"
    ap.add_argument("runs", nargs="+", type=Path,
                    help="run folders (each with result.json) or result.json files; with --coverage, tables")
    ap.add_argument("--table", type=out_path, help="CSV: one row per run (resumed if it exists; default: none, "
                                                   "required unless --coverage)")
    ap.add_argument("--coverage", action="store_true", help="only report the coverage of the given tables")
    ap.add_argument("--maze-dir", type=Path, help="where mazes named by stem live when not in data/mazes/ and the "
                                                   "run has no run.json (a bare result file) (default: none)")


def main(argv=None) -> int:
    from ..core.commands import run_command

    return run_command("calibrate", argv, prog="python -m specrefine.runs.calibrate")


def run(args, ap) -> int:
    from ..core.errors import SpecrefineError
    from ..core.runfolder import writable_parent

    try:
        if args.coverage:
            absent = [t for t in args.runs if not t.is_file()]
            if absent:
                ap.error(f"no such table: {absent[0]}")
            print(coverage_report(args.runs))
            return 0
        if args.table is None:
            ap.error("--table is required (or --coverage to read tables)")
        writable_parent(args.table)
        failed = _predict_into(args.table, args.runs, args.maze_dir)
        inside, total = table_coverage(args.table)
    except SpecrefineError as exc:
        print(f"{ap.prog}: error: {exc}", file=sys.stderr)
        return 2
    print(f"{args.table}: {_covered(inside, total)}")
    return 0 if total and not failed else 1


if __name__ == "__main__":
    from ..core.argtypes import exit_code_quiet_on_broken_pipe

    raise SystemExit(exit_code_quiet_on_broken_pipe(main))
