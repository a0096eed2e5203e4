"""Regulate a reach live from a noisy uncertainty signal, and plot what the arm did.

A simulated perception loop runs for a minute at 10 Hz. Its uncertainty estimate drifts
from certain to frightened and back, with noise; each tick it goes to an
``aou_dsl.live.regulator.Regulator`` together with the arm's state (here the arm follows its
trajectory exactly). The regulator re-plans only when the expressed state or intensity
changes by more than its hysteresis; every re-plan starts at the arm's state, so the
motion has no jump. When a reach ends, the loop starts a new one (``restart=True``).
The figure shows the signal, the expressed state over time, the distance of the hand to
the goal and the joint velocities, with every re-plan marked. Needs the media extra
(matplotlib): ``pip install ".[media]"``.

Run from the repository root::

    python examples/live_regulation.py [OUT.png | OUTPUT_FOLDER]

The figure goes to OUT.png, or to ``live-regulation.png`` in OUTPUT_FOLDER (default: a new
temporary folder).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from aou_dsl.lang.ir import State
from aou_dsl.live.regulator import Hysteresis, Regulator

DURATION = 60.0  # s
TICK = 0.1  # s: the perception loop's period
COLOURS = {State.CONFIDENT: "tab:green", State.CURIOUS: "tab:blue",
           State.HESITANT: "tab:orange", State.FEARFUL: "tab:red", State.INACTIVE: "tab:gray"}


def signal(t: np.ndarray, seed: int = 7) -> np.ndarray:
    """The estimate: certain, then growing doubt up to fear, then settling; plus noise."""
    trend = np.interp(t, [0, 8, 20, 30, 40, 48, 60], [0.02, 0.05, 0.3, 0.5, 0.74, 0.7, 0.45])
    noise = np.random.default_rng(seed).normal(0.0, 0.02, len(t))
    return np.clip(trend + noise, 0.0, 1.0)


def simulate(robot: str = "panda") -> dict:
    """The loop. Returns the executed motion on one clock (``t``, ``q``, ``qd``), the
    signal (``ticks``, ``u``), the re-plans and the expressed state's ``bands``."""
    reg = Regulator(robot, hysteresis=Hysteresis(state=0.2, intensity=0.1, uncertainty=0.06))
    ticks = np.arange(0.0, DURATION, TICK)
    u = signal(ticks)
    runs = []  # (start time, trajectory), each executed until the next starts
    replans = []
    for tick, ui in zip(ticks, u, strict=True):
        if runs:
            since, active = runs[-1]
            i = int(np.searchsorted(active.t, tick - since, side="right")) - 1
            x = (active.q[i], active.qd[i], active.qdd[i])
            at, ended = since + float(active.t[i]), tick - since >= active.duration
        else:  # at rest at the start of the reach
            x, at, ended = (reg.plan(State.CONFIDENT, 1.0).q[0], None, None), 0.0, True
        rep = reg.update(*x, uncertainty=float(ui), restart=ended,
                         elapsed=at - runs[-1][0] if runs else None)
        if rep is not None:
            runs.append((at, rep.trajectory))
            replans.append((at, rep.state, rep.intensity, rep.seconds,
                            rep.timings.get("plan", 0.0) > 0.02))
    t = np.arange(0.0, DURATION, 1.0 / 250.0)
    q = np.empty((len(t), reg.arm.n))
    qd = np.empty_like(q)
    ends = [r[0] for r in runs[1:]] + [DURATION]
    for (t0, tr), t1 in zip(runs, ends, strict=True):
        m = (t >= t0) & (t < t1)
        for j in range(reg.arm.n):
            q[m, j] = np.interp(t[m] - t0, tr.t, tr.q[:, j])
            qd[m, j] = np.interp(t[m] - t0, tr.t, tr.qd[:, j])
    bands = [(r[0], t1, r[1], r[2]) for r, t1 in zip(replans, ends, strict=True)]
    return {"reg": reg, "ticks": ticks, "u": u, "replans": replans, "bands": bands,
            "t": t, "q": q, "qd": qd}


def main(argv: list[str]) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    target = Path(argv[0]) if argv else Path(tempfile.mkdtemp(prefix="aou-live-"))
    png = target if target.suffix == ".png" else target / "live-regulation.png"
    png.parent.mkdir(parents=True, exist_ok=True)

    out = simulate()
    t, q, qd = out["t"], out["q"], out["qd"]
    reg: Regulator = out["reg"]
    pos, _ = reg.arm.fk(q[::5])
    dist = np.linalg.norm(pos - np.array(reg.goal or reg.arm.spec.goal), axis=1)

    fig, ax = plt.subplots(4, 1, figsize=(11, 9), sharex=True)
    ax[0].plot(out["ticks"], out["u"], lw=0.8, color="k", label="uncertainty estimate")
    ax[0].set_ylabel("uncertainty")
    for (t0, t1, state, level) in out["bands"]:
        for a in ax:
            a.axvspan(t0, t1, color=COLOURS[state], alpha=0.12, lw=0)
        ax[1].plot([t0, t1], [level, level], color=COLOURS[state], lw=3)
    ax[1].set_ylabel("intensity")
    ax[1].set_ylim(-0.05, 1.05)
    ax[2].plot(t[::5], dist, color="k")
    ax[2].set_ylabel("hand to goal [m]")
    ax[3].plot(t, qd, lw=0.7)
    ax[3].set_ylabel("joint velocity [rad/s]")
    ax[3].set_xlabel("time [s]")
    for r in out["replans"]:
        for a in ax:
            a.axvline(r[0], color="k", lw=0.4, ls=":")
    handles = [plt.Rectangle((0, 0), 1, 1, color=COLOURS[s], alpha=0.4) for s in State]
    fig.legend(handles, [s.value for s in State], loc="upper center", ncol=5)
    fig.savefig(png, dpi=90)
    plt.close(fig)

    warm = [r[3] * 1000 for r in out["replans"] if not r[4]]
    cold = [r[3] * 1000 for r in out["replans"] if r[4]]
    print(f"{len(out['ticks'])} ticks, {len(out['replans'])} re-plans "
          f"(states: {', '.join(sorted({r[1].value for r in out['replans']}))})")
    print(f"re-plan wall time: {len(warm)} warm, median {np.median(warm):.1f} ms; "
          f"{len(cold)} that made their plan first, median {np.median(cold):.0f} ms")
    print(f"wrote {png}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
