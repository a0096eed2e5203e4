"""Benchmark of behaviours as DMPs (docs/dmp.md), printed beside its goals.

- rollout: the hesitant behaviour's DMPs rolled out (the library's integration, every
  2 ms, then sampled at 250 Hz), and rolled out and solved for the Panda (inverse
  kinematics at every sample), each per second of motion: the median of 3;
- intensity: hesitant raised from 0.5 to 1 in its first pause, two ways. Through the DMPs
  (the running part finishes, later parts take the new intensity: the motions whose time
  scale changes are rolled out again, the rest kept from the running rollout, and the
  whole solved by inverse kinematics), and by today's live re-plan
  (:class:`aou_dsl.live.regulator.Regulator`: a synthesized, compiled, checked plan, warm, joined
  by a jerk-limited transition). Time
  of each, and smoothness over the second after the change: the largest joint jerk
  (third differences at the sample rate) and the largest step of a joint acceleration
  between two samples.
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from speed import HESITANT, figure, say


def _smoothness(t: np.ndarray, qdd: np.ndarray, t0: float) -> tuple[float, float]:
    """Largest joint jerk [rad/s^3] and acceleration step [rad/s^2] in [t0, t0 + 1]."""
    sel = (t >= t0) & (t <= t0 + 1.0)
    a, tt = qdd[sel], t[sel]
    jerk = np.abs(np.diff(a, axis=0) / np.diff(tt)[:, None]).max()
    return float(jerk), float(np.abs(np.diff(a, axis=0)).max())


def bench_dmp() -> None:
    import aou_dsl
    from aou_dsl.core.diagnostics import Span
    from aou_dsl.dmp import to_dmp
    from aou_dsl.dmp.intensity import change_intensity
    from aou_dsl.dmp.rollout import roll
    from aou_dsl.dmp.solve import to_trajectory
    from aou_dsl.lang.ir import State
    from aou_dsl.live.regulator import Regulator

    build = aou_dsl.compile(str(HESITANT))
    seq = to_dmp(build.trajectory, state="hesitant",
                 descriptors=build.measured.descriptors.to_json())
    where = Span.whole_file("<bench>")
    rolls, solves = [], []
    cache: dict = {}
    for _ in range(3):
        t = time.perf_counter()
        ro = roll(seq)
        rolls.append(time.perf_counter() - t)
        to_trajectory(seq, ro, where)
        solves.append(time.perf_counter() - t)
    motion = float(ro.t[-1])
    say(f"dmp: hesitant ({motion:.1f} s of motion, {len(seq.parts)} parts) on the Panda")
    figure("dmp_rollout_s_per_s", "DMP rollout per second of motion",
           statistics.median(rolls) / motion, "s", at_most=0.5, fmt="{:.3f}")
    figure("dmp_rollout_solved_s_per_s", "DMP rollout and IK per second of motion",
           statistics.median(solves) / motion, "s", at_most=1.0, fmt="{:.3f}")

    pause = next((a, b) for k, a, b in ro.parts if k == "pause")
    at = 0.5 * sum(pause)
    roll(seq, cache=cache)  # the running behaviour's rolled motions, kept
    t = time.perf_counter()
    changed = change_intensity(seq, at, 1.0, cache=cache)
    tr = to_trajectory(seq, changed, where)
    dmp_s = time.perf_counter() - t
    dmp_jerk, dmp_step = _smoothness(tr.t, tr.qdd, at)

    reg = Regulator("panda")
    plan = reg.plan(State.HESITANT, 0.5)
    reg.plan(State.HESITANT, 1.0)  # warm, as a prepared regulator is
    reg.replan(plan.q[0], None, None, State.HESITANT, 0.5, restart=True)
    i = int(np.searchsorted(plan.t, at))
    rep = reg.replan(plan.q[i], plan.qd[i], plan.qdd[i], State.HESITANT, 1.0)
    rt = rep.trajectory
    re_jerk, re_step = _smoothness(rt.t, rt.qdd, 0.0)
    say("  intensity 0.5 -> 1 in the first pause:      through the DMPs   re-plan (warm)")
    say(f"    time [ms]                                {dmp_s * 1000:>12.1f}   "
        f"{rep.seconds * 1000:>12.1f}")
    say(f"    largest joint jerk in 1 s [rad/s^3]      {dmp_jerk:>12.2f}   {re_jerk:>12.2f}")
    say(f"    largest acceleration step [rad/s^2]      {dmp_step:>12.4f}   {re_step:>12.4f}")
    figure("dmp_intensity_ms", "intensity change through the DMPs (roll and IK)",
           dmp_s * 1000, "ms")
    figure("dmp_intensity_vs_replan", "its time over a warm re-plan's", dmp_s / rep.seconds,
           "x")
    figure("dmp_intensity_jerk", "its largest joint jerk over the re-plan's",
           dmp_jerk / max(re_jerk, 1e-12), "x", at_most=1.0, fmt="{:.2f}")
