#!/bin/bash
# One sweep run with the code of one commit (a detached worktree), whatever the checkout holds, so that
# a session may edit specrefine/ while a long grid runs and its table stays one code's; the sweep's done rows are
# copied to a shipped table every two minutes, and a new machine resumes from that table (copied into OUT when
# OUT has none). Every argument is passed to the sweep (--out is added):
#   CODE=COMMIT OUT=runs/NAME SHIPPED=data/results/NAME.csv bash scripts/pinned_sweep.sh --mazes ... --seeds ...
# TREE: the worktree (default runs/code_COMMIT); PYTHON: the interpreter (default the checkout's .venv).
# The sweep module is the tree's own: specrefine.runs.sweep, or specrefine.sweep in a commit from before the
# sub-package layout (grids pinned to such a commit keep running through this script).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
code=${CODE:?CODE=COMMIT: the code the grid runs}
out=$(realpath -m "${OUT:?OUT=folder of the sweep}")  # absolute: the sweep runs from the worktree
shipped=$(realpath -ms "${SHIPPED:?SHIPPED=the table in data/results}")  # -s: a link there is replaced, not followed
py=${PYTHON:-$root/.venv/bin/python}
tree=${TREE:-$root/runs/code_$code}
[ -d "$tree" ] || git -C "$root" worktree add -q --detach "$tree" "$code"
if [ "$(git -C "$tree" rev-parse HEAD)" != "$(git -C "$root" rev-parse "$code^{commit}")" ]; then
    echo "$tree is not at $code: remove it (git worktree remove --force $tree) and start again" >&2
    exit 2
fi
export PYTHONPATH=$tree  # before the checkout's editable install on sys.path
if [ -f "$tree/specrefine/runs/sweep.py" ]; then sweep=specrefine.runs.sweep; else sweep=specrefine.sweep; fi
mkdir -p "$out" "$(dirname "$shipped")"
[ -s "$out/results.csv" ] || { [ -s "$shipped" ] && cp "$shipped" "$out/results.csv"; } || true

ship() {  # the table's done rows only (a row being appended is never half-copied)
    "$py" -P - "$out/results.csv" "$shipped" "$sweep" <<'PY'  # -P: the tree's code, not the cwd's
import csv, importlib, os, sys
src, dst, sweep = sys.argv[1:]
_typed, is_done = (getattr(importlib.import_module(sweep), name) for name in ("_typed", "is_done"))
with open(src, newline="") as fh:
    reader = csv.DictReader(fh)
    rows = [r for r in reader if None not in r and None not in r.values() and is_done(_typed(r))]
tmp = dst + ".tmp"
if os.path.lexists(tmp):
    os.unlink(tmp)  # a killed copy's, or a planted link: removed, never followed
with os.fdopen(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644), "w", newline="") as fh:
    w = csv.DictWriter(fh, reader.fieldnames)
    w.writeheader()
    w.writerows(rows)
os.replace(tmp, dst)  # a link at the table is replaced, never written through
PY
}
# the sleep holds none of our output streams: a caller reading them sees their end when the sweep ends
( while sleep 120 </dev/null >/dev/null 2>&1; do [ -s "$out/results.csv" ] && ship || true; done ) &
watcher=$!
trap 'kill $watcher 2>/dev/null; [ -s "$out/results.csv" ] && ship' EXIT

echo "code $(git -C "$tree" rev-parse --short HEAD) in $tree; table $out/results.csv -> $shipped"
cd "$tree"
"$py" -m "$sweep" "$@" --out "$out"
