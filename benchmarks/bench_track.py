"""Benchmark of ``--track`` (docs/checks.md, "What the arm shows"), printed beside its goals.

- speed against real time: the fearful behaviour on the Panda (12.1 s of motion) tracked
  through its servos at the controller's 1 kHz, in each servo mode, warm (the MuJoCo
  model built once): seconds of motion per second of CPU time, the median of 3;
- the added cost: ``aouc compile fearful.aou --track`` against ``aouc compile
  fearful.aou`` (a checked compile), each a fresh process as a user runs it, CPU time of
  the process, the median of 3; the figure is the ratio (a warm recompile reuses its
  episodes and is no fair base). The warm cost of the tracking alone (every mode
  simulated, each tracked motion measured and judged) is printed beside.

CPU time, not wall time: the machine is shared, and the simulation is one thread.
"""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

from speed import figure, say

FEARFUL = "behaviours/fearful.aou"


def _cpu(fn, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t = time.process_time()
        fn()
        times.append(time.process_time() - t)
    return statistics.median(times)


def _process_cpu(argv: list[str], repeat: int = 3) -> float:
    """Median CPU time [s] of a fresh ``aouc`` process running ``argv``."""
    times = []
    for _ in range(repeat):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([sys.executable, "-m", "aou_dsl", *argv], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        times.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    return statistics.median(times)


def bench_track() -> None:
    from pathlib import Path

    from aou_dsl.core.servo_specs import MODES
    from aou_dsl.driver.builder import build_file
    from aou_dsl.lang.linter import lint_file
    from aou_dsl.safety.track import track
    from aou_dsl.safety.track_report import track_modes

    path = str(Path(__file__).resolve().parent.parent / FEARFUL)
    res = build_file(path, check=True)
    tr, lint = res.trajectory.with_(path=path), lint_file(path)
    track_modes(tr, lint)  # warm: the model, the measurement's caches
    say(f"track: fearful on the Panda, {tr.duration:.1f} s of motion, servos at 1 kHz")
    for mode in MODES:
        cpu = _cpu(lambda m=mode: track(tr, m))
        figure(f"track_realtime_{mode}", f"{mode} tracking, times real time (CPU)",
               tr.duration / cpu, "x", kind="warm", at_least=20.0, fmt="{:.0f}")
    track_cpu = _cpu(lambda: track_modes(tr, lint))
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "f.json")
        plain = _process_cpu(["compile", path, "-o", out])
        tracked = _process_cpu(["compile", path, "--track", "-o", out])
    say(f"  aouc compile {plain:.2f} s CPU, with --track {tracked:.2f} s CPU (the tracking "
        f"alone, warm: {track_cpu:.2f} s)")
    figure("track_added_cost", "cold compile --track against a cold checked compile (CPU)",
           tracked / plain, "x", kind=None, at_most=2.0, fmt="{:.2f}")
