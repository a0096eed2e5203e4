"""Benchmarks of ``aouc studio``, beside their goals.

    python benchmarks/bench.py studio

- **slider release to the new motion playing** (hesitant on the Panda; cached): a studio
  runs in this process; REPEATS times a new ``pause_duration`` reaches it as the page
  sends a released slider, and the time until the new motion is on its way to the page
  (compiled, the arm's track, path and timeline sent: it plays) is taken, and beside it
  the time until its safety checks and measurement are done and its numbers sent. Each
  value is new, but only the pauses change: what the other primitives make is answered
  by what the process kept, so the figure is of the cached kind. Goal: p95 <= 200 ms to
  the motion playing.
- **cold start to the first frame of motion**: ``aouc studio FILE`` is started in a
  fresh process, Chromium (already running) opens its address, and the time from the
  start until the page's timeline marks a time past zero (the motion is playing in the
  browser) is taken; beside it, a fresh ``aouc compile`` of the same file. Goal: at
  most 3x the compile.
"""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from speed import figure, say

ROOT = Path(__file__).resolve().parent.parent
HESITANT = ROOT / "behaviours" / "hesitant.aou"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]


def _release(repeats: int) -> None:
    from aou_dsl.studio.app import Studio

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "hesitant.aou")
        shutil.copy(HESITANT, path)
        studio = Studio(path, port=0, watch=False).start()
        try:
            base = studio.sliders.values()
            playing, checked = [], []
            for k in range(repeats + 2):  # the first two warm the page's pieces
                played, shown = studio.previewed, studio.generation
                value = round(1.2 + 0.03 * k, 2)
                start = time.perf_counter()
                studio._slid({**base, "pause_duration": value})
                while studio.previewed == played:
                    time.sleep(0.001)
                playing.append(time.perf_counter() - start)
                while studio.generation == shown:
                    time.sleep(0.001)
                checked.append(time.perf_counter() - start)
            compiling = []  # the floor: the compile alone, of the same texts
            for k in range(2, repeats + 2):
                text = studio.engine.last.text.replace(
                    f"pause {round(1.2 + 0.03 * (repeats + 1), 2):g}s",
                    f"pause {round(1.2 + 0.03 * k, 2):g}s")
                start = time.perf_counter()
                studio.engine.preview(text, path)
                compiling.append(time.perf_counter() - start)
        finally:
            studio.close()
    playing, checked = playing[2:], checked[2:]
    say(f"studio: of which the compile alone: median "
        f"{1000 * float(np.median(compiling)):.0f} ms")
    say(f"studio: slider release, hesitant on the panda, {repeats} values: the new motion "
        f"plays after {1000 * float(np.median(playing)):.0f} ms (median), checked and "
        f"measured after {1000 * float(np.median(checked)):.0f} ms")
    figure("studio_release_p95_ms", "slider release to new motion playing (p95; one value "
           "new, the other primitives reused)", 1000 * float(np.percentile(playing, 95)), "ms",
           kind="cached", at_most=200.0, fmt="{:.0f}")
    figure("studio_checked_p95_ms", "slider release to its checks and numbers (p95, the same)",
           1000 * float(np.percentile(checked, 95)), "ms", kind="cached", fmt="{:.0f}")


def _cold_compile() -> float:
    with tempfile.TemporaryDirectory() as folder:
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "aou_dsl", "compile", str(HESITANT), "-o",
                        os.path.join(folder, "h.json")], check=True, capture_output=True)
        return time.perf_counter() - start


def _cold_studio(chromium: str) -> float:
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw, tempfile.TemporaryDirectory() as folder:
        ctx = pw.chromium.launch_persistent_context(
            os.path.join(folder, "profile"), executable_path=chromium, args=ARGS,
            headless=True, viewport={"width": 1280, "height": 800})
        path = os.path.join(folder, "hesitant.aou")
        shutil.copy(HESITANT, path)
        with socket.socket() as s:  # a port free now (the studio would take the next)
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        start = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-m", "aou_dsl", "studio", path, "--port",
                                 str(port)], stderr=subprocess.PIPE,
                                stdout=subprocess.DEVNULL, text=True)
        try:
            assert proc.stderr is not None
            url = ""
            for line in proc.stderr:
                if line.startswith("aouc studio: http"):
                    url = line.split()[2]
                    break
            if not url:
                raise RuntimeError("aouc studio did not start")
            threading.Thread(target=proc.stderr.read, daemon=True).start()
            page = ctx.new_page()
            page.goto(url)
            page.wait_for_function(
                "() => { const t = document.querySelector('#aou-timeline');"
                " return t && parseFloat(t.dataset.now) > 0; }", timeout=120_000)
            took = time.perf_counter() - start
        finally:
            proc.terminate()
            proc.wait(timeout=30)
            ctx.close()
    return took


def bench_studio(repeats: int = 20, release: bool = True) -> None:
    try:
        import playwright  # noqa: F401
        import viser  # noqa: F401
    except ImportError:
        say("studio: skipped (needs the studio extra and playwright: pip install '.[test]')")
        return
    if release:
        _release(repeats)
    chromium = shutil.which("chromium") or "/usr/bin/chromium"
    if not os.path.exists(chromium):
        say("studio: cold start skipped: no Chromium (apt-get install -y chromium)")
        return
    compile_s = min(_cold_compile() for _ in range(2))
    studio_s = min(_cold_studio(chromium) for _ in range(2))
    say(f"studio: cold `aouc compile` of hesitant {compile_s:.2f} s; cold `aouc studio` to "
        f"the first frame of motion in the browser {studio_s:.2f} s")
    figure("studio_cold_vs_compile", "cold studio to first frame / cold compile",
           studio_s / compile_s, "x", kind=None, at_most=3.0)
