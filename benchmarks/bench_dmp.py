"""Benchmark of behaviours as DMPs (docs/dmp.md), printed beside its goals.

- rollout: the hesitant behaviour's DMPs rolled out (the library's integration, every
  2 ms, then sampled at 250 Hz), and rolled out and solved for the Panda (inverse
  kinematics at every sample), each per second of motion: the median of 3 of the same
  sequence (cached);
- intensity: hesitant raised from 0.5 to 1 in its first pause. Through the DMPs, three
  ways: whole (the motions whose time scale changes integrated again, the whole
  behaviour solved by inverse kinematics: how it was first done), live (those motions'
  rollouts stretched in time instead, and only the samples after the change solved),
  and the live regulator's own call (``Regulator.change_intensity``: the live way plus
  the safety check of what changed). Beside them today's live re-plan
  (:meth:`aou_dsl.live.regulator.Regulator.replan`: a synthesized, compiled, checked
  plan, warm, joined by a jerk-limited transition). Wall and CPU time of each (the CPU
  time is steadier on a shared machine), and smoothness over the second after the
  change: the largest joint jerk (third differences at the sample rate) and the largest
  step of a joint acceleration between two samples. The changes are warm: a new
  intensity, from the rollouts the running behaviour keeps (as a live robot has them).
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
           statistics.median(rolls) / motion, "s", kind="cached", at_most=0.5, fmt="{:.3f}")
    figure("dmp_rollout_solved_s_per_s", "DMP rollout and IK per second of motion",
           statistics.median(solves) / motion, "s", kind="cached", at_most=1.0, fmt="{:.3f}")

    pause = next((a, b) for k, a, b in ro.parts if k == "pause")
    at = 0.5 * sum(pause)
    running = roll(seq, cache=cache)  # the running behaviour's rolled motions, kept
    first = to_trajectory(seq, running, where)
    ways = {}
    for name, retime in (("whole", False), ("live", True)):
        kept = dict(cache)
        t, c = time.perf_counter(), time.process_time()
        changed = change_intensity(seq, at, 1.0, cache=kept, running=running, retime=retime)
        tr = to_trajectory(seq, changed, where,
                           reuse=(running, first) if retime else None)
        ways[name] = (time.perf_counter() - t, time.process_time() - c, tr)
    dmp_jerk, dmp_step = _smoothness(tr.t, tr.qdd, at)

    live = Regulator("panda", through_dmp=True)
    lplan = live.plan(State.HESITANT, 0.5)
    started = live.replan(lplan.q[0], None, None, State.HESITANT, 0.5, restart=True)
    begun = started.trajectory  # the transition into the rollout, then the rollout
    k = int(np.searchsorted(begun.t, at + started.transition - 1e-9))
    c = time.process_time()
    through = live.change_intensity(begun.q[k], begun.qd[k], begun.qdd[k], 1.0,
                                    elapsed=float(begun.t[k]))
    ways["regulator"] = (through.seconds, time.process_time() - c, through.trajectory)

    reg = Regulator("panda")
    plan = reg.plan(State.HESITANT, 0.5)
    reg.plan(State.HESITANT, 1.0)  # warm, as a prepared regulator is
    reg.replan(plan.q[0], None, None, State.HESITANT, 0.5, restart=True)
    i = int(np.searchsorted(plan.t, at))
    c = time.process_time()
    rep = reg.replan(plan.q[i], plan.qd[i], plan.qdd[i], State.HESITANT, 1.0)
    replan_cpu = time.process_time() - c
    rt = rep.trajectory
    re_jerk, re_step = _smoothness(rt.t, rt.qdd, 0.0)
    say("  [warm] intensity 0.5 -> 1 in the first pause (a new intensity; the running "
        "motion's rolls kept), each way:")
    say("                                          DMPs whole   DMPs live   regulator"
        "     re-plan")
    say("    wall time [ms]                        " + "".join(
        f"{ways[w][0] * 1000:>11.1f} " for w in ("whole", "live", "regulator"))
        + f"{rep.seconds * 1000:>13.1f}")
    say("    CPU time [ms]                         " + "".join(
        f"{ways[w][1] * 1000:>11.1f} " for w in ("whole", "live", "regulator"))
        + f"{replan_cpu * 1000:>13.1f}")
    say(f"    largest joint jerk in 1 s [rad/s^3]   {dmp_jerk:>35.2f}  {re_jerk:>13.2f}")
    say(f"    largest acceleration step [rad/s^2]   {dmp_step:>35.4f}  {re_step:>13.4f}")
    say("    (the live way's joint motion equals the whole way's: "
        f"{np.abs(ways['live'][2].q - ways['whole'][2].q).max() * 1000:.3f} mrad apart)")
    dmp_s = ways["live"][0]
    figure("dmp_intensity_whole_ms", "intensity change through the DMPs, whole (roll, IK)",
           ways["whole"][0] * 1000, "ms", kind="warm")
    figure("dmp_intensity_ms", "intensity change through the DMPs, live (retimed, the "
           "remainder's IK)", dmp_s * 1000, "ms", kind="warm")
    figure("dmp_intensity_regulator_ms", "the regulator's change through the DMPs (checked)",
           ways["regulator"][0] * 1000, "ms", kind="warm")
    figure("dmp_intensity_vs_replan", "the live way's time over a warm re-plan's",
           dmp_s / rep.seconds, "x", kind=None)
    figure("dmp_intensity_jerk", "its largest joint jerk over the re-plan's",
           dmp_jerk / max(re_jerk, 1e-12), "x", kind=None, at_most=1.0, fmt="{:.2f}")
