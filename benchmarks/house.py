"""Benchmarks of the warm session and of batches (``python benchmarks/bench.py house``).

- re-lint of a changed 200-line file in a warm :class:`~aou_dsl.driver.session.Session`
  (each text new: warm);
- rebuild of a new motion in the session (every primitive's values changed: warm), and
  after one descriptor changes (the other primitives' results reused: cached), hesitant
  on the Panda, checks and measurement included;
- ``aouc compile --jobs 2`` against ``--jobs 1`` on the shipped behaviours, each a fresh
  command (cold), side by side in one run;
- the same on 2 to 20 files: never slower.
"""

from __future__ import annotations

import os
import random
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from speed import HESITANT, ROOT, _median_ms, figure, say, variant

BEHAVIOURS = sorted((ROOT / "behaviours").glob("*.aou"))


def _long_file(lines: int = 200) -> str:
    """A sequence of ``lines`` primitives, as an editor holds a long file."""
    rng = random.Random(7)
    body = []
    for i in range(lines - 3):
        pick = i % 4
        if pick == 0:
            body.append(f"  approach {rng.choice((0.01, 0.02))}m a=0.1")
        elif pick == 1:
            body.append(f"  pause {rng.choice((0.5, 0.8, 1.2))}s  # hold {i}")
        elif pick == 2:
            body.append("  retreat 0.01m a=0.1")
        else:
            body.append(f"  gaze horizontal {rng.choice((10, -10))}deg")
    return "behaviour long : hesitant\nsequence {\n" + "\n".join(body) + "\n}\n"


def _session_figures(repeat: int = 40) -> None:
    from aou_dsl.driver.session import Session

    session = Session()
    session.warm()
    text = _long_file()
    session.lint(text, "long.aou")
    edits = [text.replace("pause 0.5s", f"pause {0.5 + 0.01 * (k + 1):.2f}s", 1)
             for k in range(repeat)]
    times = []
    for e in edits:  # each text new to the session: lint runs
        t = time.perf_counter()
        session.lint(e, "long.aou")
        times.append((time.perf_counter() - t) * 1000)
    figure("session_relint_ms", "re-lint of a changed 200-line file, warm session (median)",
           statistics.median(times), "ms", kind="warm", at_most=5.0, fmt="{:.2f}")
    figure("session_relint_p95_ms", "the same, p95", sorted(times)[int(0.95 * len(times))],
           "ms", kind="warm", fmt="{:.2f}")
    hesitant = (ROOT / "behaviours" / "hesitant.aou").read_text()
    session.build(hesitant, "hesitant.aou")
    values = [f"{1.5 + 0.01 * k:.2f}s" for k in range(15)]
    builds = [hesitant.replace("1.67s", v) for v in values]
    it = iter(builds)
    ms, res = _median_ms(lambda: session.build(next(it), "hesitant.aou"), len(builds))
    assert res.ok and session.runs["build"] >= len(builds), res.diagnostics
    figure("session_recompile_ms", "rebuild after one descriptor changes, hesitant on "
           "the Panda, checks and measurement included (median)", ms, "ms", kind="cached",
           at_most=60.0)
    text = HESITANT.read_text()
    news = iter([variant(text, k) for k in range(1, 16)])
    ms, res = _median_ms(lambda: session.build(next(news), "hesitant.aou"), 15)
    assert res.ok, res.diagnostics
    figure("session_new_motion_ms", "rebuild of a new motion (every primitive changed), the "
           "same (median)", ms, "ms", kind="warm", at_most=60.0)


def _cold_batch(paths: list[str], jobs: int, out: str) -> float:
    t = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "aou_dsl", "compile", *paths, "--jobs",
                           str(jobs), "-o", out + "/"], cwd=ROOT, capture_output=True)
    assert proc.returncode == 0, proc.stderr.decode()[-2000:]
    return time.perf_counter() - t


def _batch_ratio(paths: list[str], rounds: int) -> float:
    """Median of t(--jobs 1) / t(--jobs 2) over rounds, the two interleaved."""
    ratios = []
    with tempfile.TemporaryDirectory() as out:
        for _ in range(rounds):
            one = _cold_batch(paths, 1, out + "/one")
            two = _cold_batch(paths, 2, out + "/two")
            ratios.append(one / two)
    return statistics.median(ratios)


def _load() -> str:
    """The machine's load average over the last minute: a ratio of two cores' work is
    only as good as the second core was free."""
    try:
        return f"load average {os.getloadavg()[0]:.2f}"
    except OSError:  # not reported here
        return "load average unknown"


def _batch_figures(rounds: int = 3) -> None:
    shipped = [str(p) for p in BEHAVIOURS]
    say(f"`aouc compile --jobs 2` against `--jobs 1`, each a fresh command, {rounds} rounds "
        f"interleaved (medians); {_load()} at the start")
    figure("jobs2_cold_shipped", f"--jobs 1 time / --jobs 2 time, the {len(shipped)} "
           "shipped behaviours", _batch_ratio(shipped, rounds), "x", kind="cold",
           at_least=1.5, fmt="{:.2f}")
    worst = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in (2, 5, 10, 20):
            paths = []
            for k in range(n):
                src = BEHAVIOURS[k % len(BEHAVIOURS)]
                dst = Path(tmp, f"{n}_{k:02d}_{src.name}")
                shutil.copy(src, dst)
                paths.append(str(dst))
            r = _batch_ratio(paths, rounds)
            say(f"  {n} files: --jobs 1 / --jobs 2 = {r:.2f}x ({_load()})")
            worst.append(r)
    figure("jobs2_never_slower", "the least of those ratios on 2, 5, 10 and 20 files",
           min(worst), "x", kind="cold", at_least=1.0, fmt="{:.2f}")


def bench_house() -> None:
    say("the warm session")
    _session_figures()
    _batch_figures()
