"""scripts/check_lib.sh, the helpers of the Ant check scripts: checks are skipped once done and written whole."""

import subprocess
from pathlib import Path

import pytest

SCRIPTS = Path(__file__).resolve().parent.parent / "scripts"
LIB = SCRIPTS / "check_lib.sh"
CHECK_SCRIPTS = sorted(SCRIPTS.glob("ant_*_checks.sh"))


def bash(script: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", "-euo", "pipefail", "-c", f'. "{LIB}"\n{script}'], cwd=cwd, capture_output=True,
                          text=True, timeout=30)


def test_produce_writes_a_new_file_whole(tmp_path):
    run = bash("produce out.json echo '{\"a\": 1}'", tmp_path)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "out.json").read_text() == '{"a": 1}\n'
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]


def test_produce_skips_a_file_that_holds_something(tmp_path):
    (tmp_path / "out.json").write_text("done\n")
    run = bash("produce out.json bash -c 'touch ran; echo new'", tmp_path)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "out.json").read_text() == "done\n"
    assert not (tmp_path / "ran").exists()


def test_produce_reruns_an_empty_file(tmp_path):
    (tmp_path / "out.json").write_text("")
    assert bash("produce out.json echo new", tmp_path).returncode == 0
    assert (tmp_path / "out.json").read_text() == "new\n"


def test_a_failed_check_leaves_no_file_and_stops_the_script(tmp_path):
    run = bash("produce out.json bash -c 'echo partial; exit 3'\ntouch after", tmp_path)
    assert run.returncode == 3
    assert list(tmp_path.iterdir()) == []


def test_produce_self_runs_only_when_the_file_is_missing(tmp_path):
    for _ in range(2):
        assert bash("produce_self out.json bash -c 'echo run >> calls; echo x > out.json'", tmp_path).returncode == 0
    assert (tmp_path / "calls").read_text() == "run\n"
    assert bash("produce_self missing.json false", tmp_path).returncode == 1


@pytest.fixture
def fake_python(tmp_path) -> Path:
    """A stand-in for python that prints its arguments (fails if FAIL_ON is among them)."""
    py = tmp_path / "py"
    py.write_text('#!/bin/bash\nfor a in "$@"; do [ "$a" = "${FAIL_ON:-}" ] && exit 4; done\necho "args: $*"\n')
    py.chmod(0o755)
    return py


def test_leg_kinds_md_in_the_order_given(tmp_path, fake_python):
    out = tmp_path / "checks"
    out.mkdir()
    for tag in ("old", "new"):
        for prefix in ("", "centre_"):
            for s in range(3):
                (out / f"u_chain_2_s{s}_{prefix}{tag}.json").write_text("{}")
    run = bash(f'leg_kinds_md "{out}" "{fake_python}" "old new" "centre sampled"', tmp_path)
    assert run.returncode == 0, run.stderr
    blocks = []
    for tag in ("old", "new"):
        for points, prefix in (("centre", "centre_"), ("sampled", "")):
            pattern = f"{out}/u_chain_2_s[012]_{prefix}{tag}.json"
            files = " ".join(f"{out}/u_chain_2_s{s}_{prefix}{tag}.json" for s in range(3))
            blocks.append(f"**{tag}, held-out U-chain 2 paths, {points} goal points** "
                          f"(`{fake_python} -m specrefine.experiments.legs --failures {pattern}`)\n\n"
                          f"args: -m specrefine.experiments.legs --failures {files}\n\n")
    assert (out / "leg_kinds.md").read_text() == "".join(blocks)
    assert not (out / "leg_kinds.md.tmp").exists()


def test_leg_kinds_md_fails_whole_when_one_report_fails(tmp_path, fake_python):
    out = tmp_path / "checks"
    out.mkdir()
    run = bash(f'FAIL_ON={out}/u_chain_2_s[012]_centre_new.json leg_kinds_md "{out}" "{fake_python}" "old new" '
               '"sampled centre"', tmp_path)
    assert run.returncode == 4
    assert list(out.iterdir()) == []


@pytest.mark.parametrize("script", CHECK_SCRIPTS, ids=lambda p: p.name)
def test_check_scripts_parse_and_use_the_library(script):
    assert subprocess.run(["bash", "-n", str(script)], capture_output=True).returncode == 0
    assert '. "$(dirname "$0")/check_lib.sh"' in script.read_text()
