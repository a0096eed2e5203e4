"""Benchmark of the perception loop (``aouc live``, docs/live.md), printed beside its goals.

    python benchmarks/bench_live.py

- the geometric model: one answer, the median over a scenario's ticks (warm; its goal
  sub-millisecond), and the whole loop at the controller's 100 Hz tick (perception,
  regulator, re-plans and their checks) on the card and dimming scenarios, as the p99 of
  its ticks' wall time against the 10 ms a tick has (warm: every plan made beforehand,
  as :meth:`Regulator.prepare` does for a robot that starts its loop);
- the rendered camera with detection at 320x240: frames per second, the median over a
  scenario's frames (warm: the renderer and detector made once);
- a re-plan after a change of state: from the tick that asked for it to the motion
  checked and handed to the arm, p95 over every change of state in both scenarios and a
  minute of a perception stepping through the states every 2 s (warm).

Wall times on this machine, which is shared: the load is printed beside them.
"""

from __future__ import annotations

import os
import statistics
import time
from pathlib import Path

import numpy as np
from speed import figure, say

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = [ROOT / "examples" / "scenarios" / f"{n}.toml" for n in ("occluder", "dimming")]


class _Timed:
    """A perception whose answers are timed."""

    def __init__(self, inner):
        self.inner, self.seconds = inner, []

    def perceive(self, t: float):
        clock = time.perf_counter()
        out = self.inner.perceive(t)
        self.seconds.append(time.perf_counter() - clock)
        return out


def bench_live() -> None:
    from aou_dsl.live import loop
    from aou_dsl.live.geometric import Geometric
    from aou_dsl.live.regulator import Regulator
    from aou_dsl.live.scenario import load

    say(f"live: the perception loop (load average {os.getloadavg()[0]:.1f} on "
        f"{os.cpu_count()} cores)")
    clock = time.perf_counter()
    reg = Regulator("panda", hysteresis=loop.HYSTERESIS)
    made = reg.prepare()
    figure("live_prepare_s", f"every plan made beforehand ({made} plans)",
           time.perf_counter() - clock, "s", kind="cold")
    ticks: list[float] = []
    replans: list[float] = []
    perceive: list[float] = []
    for path in SCENARIOS:
        sc = load(str(path))
        reg.rollback((None, None, None))
        timed = _Timed(Geometric(sc.scene_at))
        tick_times: list[float] = []
        real = timed.perceive

        def clocked(t: float, real=real, tick_times=tick_times):
            tick_times.append(time.perf_counter())
            return real(t)

        timed.perceive = clocked  # type: ignore[method-assign]
        r = loop.run(timed, duration=sc.duration, rate=sc.rate, regulator=reg)
        ticks += np.diff(tick_times).tolist()
        perceive += timed.seconds
        last = None
        for s in r.switches:
            if s.kind == "replan" and s.state != last:
                replans.append(s.seconds)
            if s.kind != "held":
                last = s.state
    # more changes of state: a perception that steps through the states, 2 s each
    levels = [1.0, 0.7, 0.5, 0.25, 0.0, 0.5, 1.0, 0.25, 0.7, 0.0]
    reg.rollback((None, None, None))
    r = loop.run(lambda t: levels[int(t // 2.0) % len(levels)], duration=60.0, rate=100.0,
                 regulator=reg)
    last = None
    for s in r.switches:
        if s.kind == "replan" and s.state != last:
            replans.append(s.seconds)
        if s.kind != "held":
            last = s.state
    figure("live_geometric_ms", "geometric model, one answer (median)",
           1000 * statistics.median(perceive), "ms", kind="warm", at_most=1.0, fmt="{:.2f}")
    figure("live_tick_p99_ms", "loop tick at 100 Hz, geometric model (p99)",
           1000 * float(np.percentile(ticks, 99)), "ms", kind="warm", at_most=10.0,
           fmt="{:.2f}")
    say(f"  [warm] loop ticks: median {1000 * statistics.median(ticks):.2f} ms, max "
        f"{1000 * max(ticks):.1f} ms over {len(ticks)} ticks")
    figure("live_replan_p95_ms", "re-plan after a change of state, to the arm (p95)",
           1000 * float(np.percentile(replans, 95)), "ms", kind="warm", at_most=100.0,
           fmt="{:.0f}")
    say(f"  over {len(replans)} changes of state; median {1000 * statistics.median(replans):.0f}"
        " ms")
    _camera(load(str(SCENARIOS[0])))


def _camera(sc) -> None:
    try:
        from aou_dsl.live.camera import Camera
    except ImportError:
        say("  rendered camera: skipped (the perception extra is not installed)")
        return
    cam = Camera(sc.scene_at)
    try:
        cam.perceive(0.0)  # warm
        times = []
        for t in np.arange(0.0, sc.duration, 0.5):
            clock = time.perf_counter()
            cam.perceive(float(t))
            times.append(time.perf_counter() - clock)
    finally:
        cam.close()
    figure("live_camera_hz", "rendered camera + AprilTag detection at 320x240 (median)",
           1.0 / statistics.median(times), "Hz", kind="warm", at_least=15.0, fmt="{:.1f}")


if __name__ == "__main__":
    bench_live()
