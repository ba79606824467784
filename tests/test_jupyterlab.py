"""Notebook 05 in a real JupyterLab, in headless Chromium: run all cells, move the search slider.

The test starts JupyterLab on 127.0.0.1 (a free port, token auth, config/runtime/workspace dirs and
the root dir in a temporary directory holding a copy of ``notebooks/05_astar_refinement.ipynb``;
its kernel ``specrefine``, the notebooks' own, is this interpreter with this checkout first on PYTHONPATH), opens
the notebook in Debian's Chromium (``/usr/bin/chromium``) driven by playwright, runs all cells from the Run menu
(smoke parameters: ~30 s), moves the ipywidgets slider to step 0 and checks that the picture below
it changes (the ``img`` src before and after) together with the slider's readout. The screenshot is
saved to ``tests/artifacts/jupyterlab_05_slider.png`` (gitignored; its path is printed).

Skipped, with the reason, only where no Chromium is installed (``apt-get install chromium``; ``.ci/run``
installs it when it runs as root). playwright comes with the ``dev`` extra; its own browser
download (``playwright install``) is never used.
"""

from __future__ import annotations

import os
import secrets
import shutil
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from specrefine.runs.notebook import kernel_env

REPO = Path(__file__).resolve().parent.parent
NOTEBOOK = REPO / "notebooks" / "05_astar_refinement.ipynb"
ARTIFACTS = Path(__file__).resolve().parent / "artifacts"
CHROMIUM = Path(os.environ.get("SPECREFINE_CHROMIUM", "/usr/bin/chromium"))
CHROMIUM_FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update", "--disable-sync"]
RUN_TIMEOUT_MS = 300_000

pytestmark = pytest.mark.jupyterlab


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def lab(tmp_path):
    """A JupyterLab server on a copy of notebook 05: (base url, token, log path)."""
    root = tmp_path / "root"
    (root / "notebooks").mkdir(parents=True)
    shutil.copy(NOTEBOOK, root / "notebooks" / NOTEBOOK.name)
    env = kernel_env(tmp_path / "jupyter", mpl_backend=None)  # inline figures, as in a reader's lab
    env["PYTHONPATH"] = os.pathsep.join([str(REPO), *filter(None, [env.get("PYTHONPATH")])])
    for name in ("JUPYTER_CONFIG_DIR", "JUPYTER_RUNTIME_DIR", "JUPYTERLAB_SETTINGS_DIR", "JUPYTERLAB_WORKSPACES_DIR"):
        env[name] = str(tmp_path / name.lower())
    news = tmp_path / "jupyterlab_settings_dir" / "@jupyterlab" / "apputils-extension"
    news = news / "notification.jupyterlab-settings"
    news.parent.mkdir(parents=True)
    news.write_text('{"fetchNews": "false", "checkForUpdates": false}')  # no "Jupyter news?" popup, no fetch
    port, token = _free_port(), secrets.token_hex(16)
    log_path = tmp_path / "jupyterlab.log"
    cmd = [sys.executable, "-m", "jupyterlab", "--no-browser", "--ip=127.0.0.1", f"--port={port}",
           "--ServerApp.port_retries=0", f"--IdentityProvider.token={token}", f"--ServerApp.root_dir={root}",
           "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate", "--LabApp.news_url=None",
           "--LabApp.expose_app_in_browser=True", "--LabApp.extension_manager=readonly",
           "--ServerApp.terminals_enabled=False"] + (["--allow-root"] if os.geteuid() == 0 else [])
    with log_path.open("w") as log:
        proc = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 90
        while True:
            try:
                with urllib.request.urlopen(f"{base}/api/status?token={token}", timeout=5) as r:
                    if r.status == 200:
                        break
            except OSError:
                pass
            if proc.poll() is not None or time.monotonic() > deadline:
                pytest.fail(f"JupyterLab did not start (exit {proc.poll()}):\n{log_path.read_text()[-3000:]}")
            time.sleep(0.5)
        yield base, token, log_path
    finally:
        proc.terminate()  # the server shuts its kernels down
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, 9)  # the server's own process group, nothing else
            proc.wait()


def test_slider_redraws_the_search_in_jupyterlab(lab):
    if not CHROMIUM.exists():
        pytest.skip(f"no Chromium at {CHROMIUM}: install it (apt-get install chromium; .ci/run does this as root) "
                    "or point SPECREFINE_CHROMIUM at one")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.fail("playwright is missing: it is in the dev extra (pip install -e '.[dev]', or make venv)")
    base, token, log_path = lab
    ARTIFACTS.mkdir(exist_ok=True)
    shot = ARTIFACTS / "jupyterlab_05_slider.png"
    t0 = time.monotonic()
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_FLAGS)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 1100})
            outside = []  # every request must stay on the test's server
            page.on("request", lambda r: r.url.startswith(("data:", "blob:", base)) or outside.append(r.url))
            page.goto(f"{base}/lab/tree/notebooks/{NOTEBOOK.name}?reset&token={token}")
            page.wait_for_selector(".jp-NotebookPanel .jp-Cell", timeout=120_000)
            # the kernel (ours: a specrefine spec at the front of JUPYTER_PATH) must be up before running
            page.wait_for_function("""() => {
                const w = window.jupyterapp && window.jupyterapp.shell.currentWidget;
                const k = w && w.sessionContext && w.sessionContext.session && w.sessionContext.session.kernel;
                return k && k.status === 'idle';
            }""", timeout=120_000)

            page.click("li.lm-MenuBar-item:has-text('Run')")
            page.click("li.lm-Menu-item[data-command='runmenu:run-all']")
            # the last cell records 'search_events' when everything above it has run
            page.wait_for_selector("text=search_events =", timeout=RUN_TIMEOUT_MS)
            errors = page.locator(".jp-OutputArea-output[data-mime-type='application/vnd.jupyter.stderr']"
                                  ":has-text('Traceback')")
            assert errors.count() == 0, errors.first.inner_text()

            widget = page.locator(".jp-OutputArea-output .widget-vbox").first
            widget.wait_for(timeout=60_000)
            image = widget.locator("img").first
            image.wait_for(timeout=60_000)
            readout = widget.locator(".widget-readout").first
            src_js = "() => { const i = document.querySelector('.jp-OutputArea-output .widget-vbox img'); " \
                     "return i ? i.getAttribute('src') : null; }"
            before_src, before_step = page.evaluate(src_js), readout.inner_text()
            handle = widget.locator(".noUi-handle").first
            handle.scroll_into_view_if_needed()
            handle.focus()
            page.keyboard.press("Home")  # noUiSlider's keyboard: to the minimum, step 0
            page.wait_for_function(f"(before) => {{ const s = ({src_js})(); return s && s !== before; }}",
                                   arg=before_src, timeout=60_000)
            after_src, after_step = page.evaluate(src_js), readout.inner_text()
            widget.scroll_into_view_if_needed()
            page.screenshot(path=str(shot), full_page=False)
        except Exception:
            page.screenshot(path=str(ARTIFACTS / "jupyterlab_failure.png"))
            (ARTIFACTS / "jupyterlab_failure.html").write_text(page.content())
            print(f"\nfailure screenshot and page: {ARTIFACTS}/jupyterlab_failure.png, .html; server log {log_path}")
            raise
        finally:
            browser.close()
    elapsed = time.monotonic() - t0
    print(f"\nJupyterLab screenshot: {shot}  (browser part {elapsed:.0f} s; server log {log_path})")
    assert not outside, f"the page requested outside the local server: {outside[:5]}"
    assert before_step != after_step and after_step.strip() == "0", (before_step, after_step)
    assert before_src and after_src != before_src, "the picture under the slider did not change"
