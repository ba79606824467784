"""Issue 13: random bytes as maze files, replay lines and VLM replies give a result or one line, never a
traceback or a hang.

Every example runs ``specrefine refine`` in-process with tiny budgets under a time limit (an alarm that
fails the example instead of letting it hang) and ends in one of two ways: exit 0 with a valid
result.json, or exit 2 with exactly one line from the CLI on stderr.  Log records (warnings before an
error, e.g. skipped replay lines) go to their own stream; they too must hold no traceback.  Twelve examples
per test by default (derandomized, about 45 s in all); ``FUZZ_N=200`` searches longer, at random.
"""

from __future__ import annotations

import contextlib
import io
import json
import logging
import os
import shutil
import signal
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from test_vlm import GOOD, KEY, Server

from specrefine.cli import main as cli_main
from specrefine.core.errors import MazeError
from specrefine.core.mazes import Maze, load_maze

TINY = ["-w", "1", "-d", "1", "--rollouts", "2", "--episodes", "2"]
LIMIT_S = 60  # per example: far above a tiny run, far below a hang


@contextlib.contextmanager
def time_limit(seconds: int):
    def expire(*_):
        raise TimeoutError(f"no result within {seconds} s")

    old = signal.signal(signal.SIGALRM, expire)
    signal.alarm(seconds)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, old)


def refine(*args: str) -> tuple[int, str, str, Path]:
    """Exit code, the CLI's stderr, the log records and the run folder of ``specrefine refine ARGS``."""
    out = Path(tempfile.mkdtemp(prefix="fuzz_"))
    return (*captured(cli_main, ["refine", *args, "--out", str(out / "run"), *TINY]), out)


def captured(main, argv: list[str]) -> tuple[int, str, str]:
    """Exit code, stderr and the log records of ``main(argv)``, within the time limit."""
    err, logs = io.StringIO(), io.StringIO()
    handler = logging.StreamHandler(logs)
    logging.getLogger().addHandler(handler)
    try:
        with time_limit(LIMIT_S), contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            try:
                code = main(argv)
            except SystemExit as exc:  # argparse, p.exit
                code = exc.code
    finally:
        logging.getLogger().removeHandler(handler)
    return code, err.getvalue(), logs.getvalue()


def assert_result_or_one_line(code, err, logs, out):
    event(f"exit {code}")  # --hypothesis-show-statistics: how often each ending was reached
    try:
        assert "Traceback" not in err + logs, err + logs
        if code == 0:
            data = json.loads((out / "run" / "result.json").read_text())
            lo, hi = data["success_ci"]
            assert 0 <= lo <= data["success_rate"] <= hi <= 1 and data["episodes"] == 2, data
        else:
            lines = err.strip().splitlines()
            assert code == 2 and len(lines) == 1 and lines[0].startswith("specrefine: error: "), (code, err)
    finally:
        shutil.rmtree(out, ignore_errors=True)


FUZZ_N = os.environ.get("FUZZ_N")  # a longer, random search: FUZZ_N=200 pytest tests/test_reliability_fuzz.py
FUZZ = settings(max_examples=int(FUZZ_N or 12), derandomize=FUZZ_N is None, deadline=None,
                suppress_health_check=[HealthCheck.too_slow])


# --- maze files -----------------------------------------------------------------------------------------
GRID_ROW = st.text(alphabet="#.SGab~", min_size=1, max_size=7)
ROOM = b"; a room\n#######\n#S.a.G#\n#..~..#\n#######\n"


@st.composite
def mutated_room(draw) -> bytes:
    """The room with a few bytes replaced: often still a maze, sometimes just not."""
    data = bytearray(ROOM)
    for _ in range(draw(st.integers(0, 3))):
        data[draw(st.integers(0, len(data) - 1))] = draw(st.sampled_from(b"#.SGab~;\n\xff"))
    return bytes(data)


MAZE_TEXT = st.one_of(
    mutated_room(), mutated_room(),
    st.binary(max_size=160),
    st.text(alphabet="#.SGab~ \t;:\r\n\ufeff\u00e9\x00", max_size=160).map(str.encode),
    st.tuples(st.sampled_from(["", "; spec: b -> G\n", "; spec: (a | b) -> G\n", "; spec: ->\n", "; spec: z\n"]),
              st.lists(GRID_ROW, min_size=1, max_size=6).map("\n".join))
    .map(lambda parts: (parts[0] + parts[1]).encode()),
)


@FUZZ
@given(data=MAZE_TEXT)
def test_random_maze_files_give_a_maze_or_one_line(tmp_path_factory, data):
    path = tmp_path_factory.mktemp("maze") / "fuzz.maze"
    path.write_bytes(data)
    try:
        assert isinstance(load_maze(path), Maze)
    except MazeError as exc:
        assert "\n" not in str(exc) and str(exc).startswith(str(path)), exc
    assert_result_or_one_line(*refine(str(path), "--method", "ours"))


# --- VLM replies ----------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def fake_vlm():
    server = Server()
    old = {name: os.environ.get(name) for name in ("OPENAI_API_KEY", "OPENAI_BASE_URL", "SPECREFINE_VLM_DEADLINE")}
    os.environ.update(OPENAI_API_KEY=KEY, OPENAI_BASE_URL=server.base, SPECREFINE_VLM_DEADLINE="30")
    yield server
    for name, value in old.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value
    server.close()


VLM_RUN = ("split_doorway", "--method", "ours", "--proposer", "litellm:openai/test-model")
REPLAY_RUN = ("split_doorway", "--method", "ours", "--proposer")


REPLY = st.one_of(st.binary(max_size=200),  # a raw HTTP 200 body
                  st.text(max_size=200).map(lambda text: [text]),  # one answer's text
                  st.sampled_from([b"{}", b"null", b'{"choices": []}', b'{"choices": [{"message": null}]}', [GOOD]]))


@FUZZ
@given(replies=st.lists(REPLY, min_size=1, max_size=4))
def test_random_vlm_replies_give_a_result_or_one_line(fake_vlm, replies):
    fake_vlm.script[:] = list(replies)  # then good answers
    assert_result_or_one_line(*refine(*VLM_RUN))


# --- replay lines ---------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def recording(fake_vlm, tmp_path_factory) -> list[bytes]:
    """The lines of a recorded run (good answers) that the replays below repeat, edited."""
    fake_vlm.script.clear()
    code, err, _, out = refine(*VLM_RUN)
    assert code == 0, err
    lines = (out / "run" / "vlm_recording.jsonl").read_bytes().splitlines()
    shutil.rmtree(out)
    return lines


def answer_text(line: bytes, text: str) -> bytes:
    """A recorded call with its answers replaced by ``text`` (a line that is no recorded call stays as it is)."""
    try:
        record = json.loads(line)
        for choice in record["response"]["choices"]:
            choice["text"] = text
    except (ValueError, KeyError, TypeError):
        return line
    return json.dumps(record).encode()


EDIT = st.one_of(st.tuples(st.just("answer"), st.integers(0, 9), st.text(max_size=60)),
                 st.tuples(st.just("insert"), st.integers(0, 9), st.binary(max_size=60)),
                 st.tuples(st.just("cut"), st.integers(0, 9), st.integers(0, 400)),
                 st.tuples(st.just("drop"), st.integers(0, 9), st.none()))


def edited(lines: list[bytes], edits) -> list[bytes]:
    lines = list(lines)
    for kind, at, value in edits:
        if kind == "insert":
            lines.insert(at % (len(lines) + 1), value)
            continue
        if not lines:
            continue
        i = at % len(lines)
        if kind == "answer":
            lines[i] = answer_text(lines[i], value)
        elif kind == "cut":
            lines[i] = lines[i][:value]
        else:
            del lines[i]
    return lines


@FUZZ
@given(edits=st.lists(EDIT, max_size=3))
def test_edited_replay_lines_give_a_result_or_one_line(recording, tmp_path_factory, edits):
    path = tmp_path_factory.mktemp("replay") / "rec.jsonl"
    path.write_bytes(b"\n".join(edited(recording, edits)) + b"\n")
    assert_result_or_one_line(*refine(*REPLAY_RUN, f"replay:{path}"))


# --- issue 29: every command, random argument vectors and random bytes as files -----------------------------
# Each `python -m specrefine.*` command with a command line and `specrefine refine` (above), run in-process under a
# time limit: exit 0, or exit 2 with exactly one line on stderr (log records go to their own stream and hold no
# traceback).  Options that would start long work get tiny values; `python -m specrefine.pictures.render` takes no
# arguments and rewrites the shipped maze pictures, so it is left out.  Three examples per command by default.
from importlib import import_module  # noqa: E402

CMD_FUZZ = settings(max_examples=int(FUZZ_N or 3), derandomize=FUZZ_N is None, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
JUNK = st.one_of(st.sampled_from(["--bogus", "-x", "", "--", "nan", "-1", "0", "1e9", "\u00e9", "--out"]),
                 st.text(alphabet="ab-=:/._ 0\u00e9", max_size=8))


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished one-cell sweep: its table and its cell's run folder (result.json, run.json)."""
    from specrefine.runs import sweep

    out = tmp_path_factory.mktemp("finished")
    assert sweep.main(["--mazes", "u_chain_1", "--methods", "ours", "--proposers", "geometric", "--seeds", "0",
                       "--rollouts", "2", "--episodes", "2", "--workers", "1", "--out", str(out)]) == 0
    (cell,) = (out / "cells").iterdir()
    return {"table": str(out / "results.csv"), "run": str(cell), "result": str(cell / "result.json")}


def choice(valid, invalid):
    return st.one_of(st.sampled_from(valid), st.sampled_from(invalid))


def command_argv(name: str, files: dict):
    """A strategy of argument vectors for command ``name``; ``files``: paths of good inputs and random-bytes ones."""
    bad, out = files["random"], files["out"]
    options = {
        "sweep": (["--methods", "dirl", "--seeds", "0", "--rollouts", "2", "--episodes", "2", "--workers", "1",
                   "--out", out], {"--mazes": choice(["u_maze", "u_maze=G"], [bad, "no_such", "u_maze=->"]),
                                   "--proposers": choice(["geometric", "geometric:max_waypoints=4"], ["gpt", bad]),
                                   "--methods": choice(["dirl"], ["nonsense"]), "--agent": choice(["point"], ["x"]),
                                   "--specs": choice(["G"], ["(G", "z"]), "--policy": choice(["shipped"], [bad]),
                                   "--evaluation": choice(["fixed"], ["slow"]), "--seeds": choice(["1"], ["-1"])}),
        "calibrate": ([], {"--table": choice([out + ".csv"], ["", files["dir"]]), "--coverage": st.just(None),
                           "--maze-dir": choice([files["dir"]], [bad])}),
        "failures": (["--episodes", "2"], {"--episodes": choice(["1"], ["0", "-5", "x"]),
                                           "--seed": choice(["3"], ["-1"]),
                                           "--out": choice([out + ".json"], ["", files["dir"], bad + "/sub"]),
                                           "--policy": choice(["shipped"], [bad])}),
        "comparison": (["--out", out], {"--grid": choice(["point", "ant"], ["cat"]),
                                        "--out": choice([out], ["", bad])}),
        "figures": (["--out", out], {"--out": choice([out], ["", bad])}),
        "repair_claims": (["--out", out], {"--out": choice([out], ["", bad])}),
        "train": (["--agent", "point", "--frames", "64", "--num-envs", "2", "--steps-per-env", "4", "--no-progress",
                   "--out", out], {"--init": choice(["point"], [bad, "ant"]), "--resume": st.just(None),
                                   "--evaluate": choice(["point"], [bad]), "--episodes": choice(["2"], ["0"]),
                                   "--agent": choice(["point"], ["walker"]), "--switch-radius": st.just("1 0.5")}),
        "notebook": (["executed", "--out", out], {"--tier": choice(["smoke"], ["huge"]),
                                                   "--out": choice([out], [""])}),
        "bench": ([], {}),
    }
    fixed, opts = options[name]
    positional = {"calibrate": choice([files["run"], files["result"]], [bad, files["dir"]]),
                  "failures": choice([files["result"]], [bad, files["dir"]]),
                  "comparison": choice([files["table"]], [bad]), "figures": choice([files["table"]], [bad]),
                  "repair_claims": choice([files["table"]], [bad]),
                  "notebook": st.sampled_from(["zz_no_such_notebook", "99"]),
                  "bench": st.sampled_from([["evaluator", "--seconds", "0.05", "--rounds", "1", "--batch", "2"],
                                            ["evaluator", "--scenario", bad], ["evaluator", "--batch", "0"],
                                            ["refine", "--agent", "point", "--mazes", "u_maze", "--seeds", "0",
                                             "--method", "dirl", "--episodes", "2"],
                                            ["refine", "--method", "best"], ["refine", "--proposer", bad],
                                            ["refine", "--mazes", bad], ["cook"]])}.get(name)

    @st.composite
    def build(draw):
        argv = list(fixed)
        if positional is not None:
            first = draw(positional)
            argv = (first if isinstance(first, list) else [first]) + argv
        for flag in draw(st.lists(st.sampled_from(sorted(opts)), max_size=3, unique=True)) if opts else []:
            value = draw(opts[flag])
            argv += [flag] if value is None else [flag, *value.split(" ")] if flag == "--switch-radius" else \
                [flag, value]
        if draw(st.booleans()):
            argv.insert(draw(st.integers(0, len(argv))), draw(JUNK))
        return [str(a) for a in argv]

    return build()


COMMANDS = {"sweep": "specrefine.runs.sweep", "calibrate": "specrefine.runs.calibrate",
            "failures": "specrefine.experiments.failures", "comparison": "specrefine.experiments.comparison",
            "figures": "specrefine.experiments.figures", "repair_claims": "specrefine.experiments.repair_claims",
            "train": "specrefine.sim.train", "notebook": "specrefine.runs.notebook",
            "bench": "specrefine.bench.__main__"}


def run_command(module: str, argv: list[str]) -> tuple[int, str, str]:
    return captured(import_module(module).main, argv)


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_every_command_gives_exit_0_or_one_line(name, finished, tmp_path_factory):
    @CMD_FUZZ
    @given(data=st.data(), blob=st.binary(max_size=300))
    def check(data, blob):
        where = tmp_path_factory.mktemp(name)
        (where / "random.bin").write_bytes(blob)
        (where / "dir").mkdir()
        files = {**finished, "random": str(where / "random.bin"), "out": str(where / "out"), "dir": str(where / "dir")}
        argv = data.draw(command_argv(name, files), label="argv")
        code, err, logs = run_command(COMMANDS[name], argv)
        event(f"exit {code}")
        assert "Traceback" not in err + logs, (argv, err + logs)
        if code != 0:
            lines = err.strip().splitlines()
            assert code == 2 and len(lines) == 1, (argv, code, err[-3000:])

    check()
