"""Reading results tables: every row or a one-line error, never a row silently dropped, merged or duplicated.

The sweep writes these tables (``specrefine.runs.sweep``); the analysis, calibration and figures read them here.
"""

from __future__ import annotations

import csv
import io
import os
from pathlib import Path

from .errors import SweepError
from .paper import PAPER
from .paths import regular_file

KNOBS = ("w", "d", "k")  # the search settings a sweep can vary; a table from before their columns ran the paper's


def csv_text(rows: list[dict], columns) -> str:
    """``rows`` as CSV text with a header of ``columns`` (quoted where needed, "\\n" line ends), for write_atomic."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, columns, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def goal_points_of(row: dict) -> str:
    """Where a row's (or a result's, or a run configuration's) legs aimed: ``goal_points``, the paper's rule for
    tables and results from before the option."""
    return row.get("goal_points") or PAPER.goal_points


def read_table(path) -> list[dict]:
    """The rows of a results table, typed (numbers as numbers); [] where there is no table yet.

    A table that does not parse as the sweep writes it (a row with another number of fields than the header, an
    unterminated quote, bytes that are not UTF-8 text, a number column holding text) is a one-line
    :class:`SweepError` naming the file and line: no row is dropped, merged or duplicated behind the user's back.
    Only the last row may be short, when the file ends without a newline: a row cut off by a kill (not done)."""
    path = Path(path)
    if not path.exists():
        return []
    defaults = {knob: getattr(PAPER, knob) for knob in KNOBS}  # tables from before w, d, k ran the paper's
    return [{**defaults, **_typed(r)} for r in _raw_rows(path)[1]]


def read_checked_table(path) -> list[dict]:
    """``read_table`` of a table that must exist, for the commands that only read one (comparison, figures)."""
    if not os.path.lexists(path):
        raise SweepError(f"no table at {path}")
    if not _raw_rows(regular_file(path, "table"))[0]:
        raise SweepError(f"{path}: an empty table (no header row)")
    return read_table(path)


def _raw_rows(path: Path) -> tuple[list[str], list[dict]]:
    """(header, rows as text) of a table, checked as ``read_table`` says."""
    try:
        text = regular_file(path, "table").read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise SweepError(f"{path}: not a results table (not UTF-8 text)") from None
    except OSError as exc:
        raise SweepError(f"{path}: cannot read the table ({exc.strerror or exc})") from None
    if "\0" in text:
        raise SweepError(f"{path}: not a results table (it holds NUL bytes)")
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    header, rows, short, start = None, [], None, 1
    try:
        for fields in reader:
            start, line = reader.line_num + 1, start  # where this record began; the next one begins after it
            if not fields:
                continue
            if header is None:
                header = fields
                continue
            if short is not None or len(fields) > len(header):
                bad = short or (line, len(fields))
                raise SweepError(f"{path}:{bad[0]}: a malformed row ({bad[1]} fields, the header has {len(header)}): "
                                 "fix or remove that line")
            if len(fields) < len(header):
                short = (line, len(fields))
            rows.append(dict(zip(header, fields + [""] * (len(header) - len(fields)))))
    except csv.Error as exc:
        raise SweepError(f"{path}:{start}: a malformed row ({exc}): fix or remove that line") from None
    if short is not None and text.endswith("\n"):  # not cut off by a kill
        raise SweepError(f"{path}:{short[0]}: a malformed row ({short[1]} fields, the header has {len(header)}): "
                         "fix or remove that line")
    for row in rows:
        for key in _NUMBERS:
            if row.get(key) not in (None, "") and not _is_number(row[key]):
                raise SweepError(f"{path}: row of cell {row.get('cell', '?')!r}: {key} is {row[key][:40]!r}, "
                                 "not a number")
    return header or [], rows


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


_TEXT = ("policy_fingerprint", "commit")  # hex digests: "123e45678901" or "1461726" must not become a number


def _typed(row: dict) -> dict:
    out = {}
    for k, v in row.items():
        if k in _TEXT:
            out[k] = v
        elif v in ("True", "False"):
            out[k] = v == "True"
        else:
            try:
                out[k] = int(v) if k in ("seed", "episodes", "evaluations", "sim_steps", "vlm_calls",
                                                "proposer_calls", *KNOBS) else float(v)
            except (TypeError, ValueError):
                out[k] = v
    return out


#: a row is done only when these hold numbers (a row cut short by a kill has empty fields)
_NUMBERS = ("success_rate", "success_ci_low", "success_ci_high", "episodes", "evaluations", "graph_vertices")
