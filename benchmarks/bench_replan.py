"""Benchmark of live re-planning: a mid-motion re-plan, warm, beside its goal (<= 100 ms).

    python benchmarks/bench_replan.py [ROBOT] [REPEATS]

A :class:`aou_dsl.live.regulator.Regulator` has its plans made once (cold: synthesis, compile and
the safety checks of the whole plan; printed too). Then, REPEATS times (default 20), the
arm starts a confident reach, and at a different instant of it, while it moves, the
estimate turns hesitant: the re-plan from that state (q, qd, qdd) is timed. Warm means
the hesitant plan is already made; the re-plan then finds where the arm is along its
reach, joins the plan, computes the jerk-limited transition and checks it. The figures
are wall times on this machine, with where the time goes.
"""

from __future__ import annotations

import gc
import statistics
import sys
import time

import numpy as np


def main(argv: list[str]) -> int:
    from aou_dsl.lang.ir import State
    from aou_dsl.live.regulator import Regulator

    robot = argv[0] if argv else "panda"
    repeats = int(argv[1]) if len(argv) > 1 else 20
    clock = time.perf_counter()
    reg = Regulator(robot)
    load = time.perf_counter() - clock
    cold = {}
    for state in (State.CONFIDENT, State.HESITANT):
        clock = time.perf_counter()
        reg.plan(state, 0.5)
        cold[state] = time.perf_counter() - clock
    start = reg.plan(State.CONFIDENT, 0.5)
    reg.replan(start.q[0], None, None, State.CONFIDENT, 0.5, restart=True)  # warm-up

    walls: list[float] = []
    steps: dict[str, list[float]] = {}
    moving = np.flatnonzero(np.abs(start.qd).max(axis=1) > 0.05)
    picks = moving[np.linspace(0, len(moving) - 1, repeats).astype(int)]
    for k in picks:
        first = reg.replan(start.q[0], None, None, State.CONFIDENT, 0.5, restart=True)
        tr = first.trajectory
        i = min(int(k), len(tr.t) - 1)
        gc.disable()
        rep = reg.replan(tr.q[i], tr.qd[i], tr.qdd[i], State.HESITANT, 0.5)
        gc.enable()
        walls.append(rep.seconds)
        for name, seconds in rep.timings.items():
            steps.setdefault(name, []).append(seconds)

    first = reg.replan(start.q[0], None, None, State.CONFIDENT, 0.5, restart=True)
    i = int(picks[len(picks) // 2])
    tr = first.trajectory
    miss = reg.replan(tr.q[i], tr.qd[i], tr.qdd[i], State.FEARFUL, 0.5)

    ms = sorted(w * 1000 for w in walls)
    print(f"live re-plan on {robot}: {repeats} mid-motion re-plans, confident -> hesitant")
    print(f"  [cold] once: loading the arm {load * 1000:.0f} ms; making a plan "
          + ", ".join(f"{s} {t * 1000:.0f} ms" for s, t in cold.items()))
    print(f"  [warm] re-plan: median {statistics.median(ms):.1f} ms, "
          f"90th percentile {ms[int(0.9 * (len(ms) - 1))]:.1f} ms, max {ms[-1]:.1f} ms "
          f"(goal <= 100 ms: {'met' if statistics.median(ms) <= 100 else 'NOT met'})")
    print("  [warm] where the time goes (median): " + ", ".join(
        f"{name} {statistics.median(v) * 1000:.1f} ms" for name, v in steps.items()))
    print(f"  [warm] a re-plan into a plan not made yet (synthesis, compile, checks): "
          f"{miss.seconds * 1000:.0f} ms, of which making the plan "
          f"{miss.timings['plan'] * 1000:.0f} ms (Regulator.prepare() avoids it)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
