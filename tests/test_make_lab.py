"""`make lab` starts JupyterLab on the notebooks, as root too (LAB_ARGS: --allow-root when the uid is 0)."""

from __future__ import annotations

import os
import secrets
import shlex
import shutil
import socket
import subprocess
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="no make")


def lab_command(*assignments: str) -> list[str]:
    """The `jupyter lab` command line `make lab` runs (a dry run: nothing is started or installed)."""
    dry = subprocess.run(["make", "--no-print-directory", "-n", "lab", *assignments], cwd=ROOT, capture_output=True,
                         text=True, check=True)  # a sub-make (the suite run by `make test`) prints no directory lines
    line = dry.stdout.replace("\\\n", " ").splitlines()[-1]
    assert "jupyter lab" in line, dry.stdout
    return shlex.split(line)


def test_as_root_make_lab_allows_root_and_lab_args_replace_it():
    assert ("--allow-root" in lab_command()) == (os.geteuid() == 0)
    chosen = lab_command("LAB_ARGS=--ServerApp.open_browser=False")
    assert "--ServerApp.open_browser=False" in chosen and "--allow-root" not in chosen
    assert "--MappingKernelManager.default_kernel_name=specrefine" in chosen


def test_the_command_make_lab_runs_starts_jupyterlab(tmp_path):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    token = secrets.token_hex(8)
    command = lab_command(f"LAB_PORT={port}")
    command[0] = str(ROOT / command[0])  # .venv/bin/jupyter, from the checkout
    env = {**os.environ, **{name: str(tmp_path / name.lower()) for name in (
        "JUPYTER_CONFIG_DIR", "JUPYTER_RUNTIME_DIR", "JUPYTERLAB_SETTINGS_DIR", "JUPYTERLAB_WORKSPACES_DIR")}}
    log = (tmp_path / "lab.log").open("w")
    proc = subprocess.Popen([*command, "--no-browser", f"--IdentityProvider.token={token}",
                             "--ServerApp.port_retries=0", "--LabApp.news_url=None"], cwd=ROOT, env=env,
                            stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.monotonic() + 90
        while True:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/api/status?token={token}", timeout=5) as r:
                    assert r.status == 200
                    break
            except OSError:
                pass
            assert proc.poll() is None, (tmp_path / "lab.log").read_text()[-2000:]
            assert time.monotonic() < deadline, "JupyterLab did not answer in 90 s"
            time.sleep(0.5)
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, 9)  # the server's own process group, nothing else
            proc.wait()
