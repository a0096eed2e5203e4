"""Whether a recording's clock can be trusted: a logger that stamps each sample when it
arrives, not when it was taken, moves every reading of a rate by the stamps' error.

The positions then advance at their own steady pace while the stamps jitter, and every
re-noised copy (:mod:`.uncertainty`) keeps the same clock, so the intervals stay narrow
about a wrong value. :func:`stamp_share` tells such a clock from one whose stamps are
the samples' own times; :func:`judge_stamps` reads the recording again on its clock
evened out (:func:`evened`) and widens each interval to take that reading in. When the
reading on the recording's own clock contradicts its joints (R406), such a recording is
read on the clock evened out instead, and says so (:func:`read_on_evened`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np

from ..core.codes import R411
from ..core.diagnostics import AouError, Span, diag
from .recognisers import every_named
from .signal import centred_mean
from .uncertainty import vague

__all__ = ["STAMP_FOLLOW", "evened", "judge_stamps", "read_on_evened", "stamp_share",
           "stamped_on_arrival"]


#: Fewest steps of clear motion on which the clock's stamps are judged.
STAMP_STEPS = 80
#: Least spread of the clock's steps (their std over their median) worth judging: a
#: clock steadier than this moves no reading.
STAMP_JITTER = 0.1
#: The stamps follow the samples when the positions' steps follow the clock's by at
#: least this share (1 when each stamp is its sample's time; 0 when the stamps are taken
#: on arrival and the samples were made at their own steady pace).
STAMP_FOLLOW = 0.7
#: Samples over which a clock that does not follow its samples is evened out.
STAMP_WINDOW = 21


def stamp_share(t: np.ndarray, q: np.ndarray, noise: np.ndarray) -> float | None:
    """How much of the clock's jitter the positions follow: the slope of each step of
    the joint that moved most, over its local pace, against the clock's step over its
    median (1 when each stamp is the time its sample was taken, 0 when the stamps are
    taken on arrival and the samples came at a steady pace). None when the clock is
    steady (its steps vary less than :data:`STAMP_JITTER`) or the motion too short or
    too slow to judge (fewer than :data:`STAMP_STEPS` steps each more than 3 times the
    joint's noise)."""
    dt = np.diff(t)
    h = float(np.median(dt))
    if len(dt) < STAMP_STEPS or float(np.std(dt)) < STAMP_JITTER * h:
        return None
    j = int(np.argmax(np.ptp(q, axis=0)))
    k = 5
    dq = np.diff(q[:, j])
    pace = (q[2 * k:, j] - q[:-2 * k, j]) / (t[2 * k:] - t[:-2 * k])  # over 10 steps
    step, gap = dq[k:len(dq) - k + 1], dt[k:len(dt) - k + 1]
    n = min(len(step), len(pace))
    step, gap, pace = step[:n], gap[:n], pace[:n]
    clear = (np.abs(step) > 3 * max(float(noise[j]), 1e-12)) & \
        (np.abs(pace) * h > 3 * max(float(noise[j]), 1e-12))
    if int(clear.sum()) < STAMP_STEPS:
        return None
    x = gap[clear] / h - 1.0
    y = step[clear] / (pace[clear] * h) - 1.0
    if float(np.dot(x, x)) <= 0.0:
        return None
    return float(np.dot(x, y) / np.dot(x, x))


def evened(t: np.ndarray, window: int = STAMP_WINDOW) -> np.ndarray:
    """A clock's stamps averaged over ``window`` samples (fewer, symmetric, at its ends):
    it still increases strictly, keeps a logging gap's time (spread over the window)
    and loses the stamps' jitter."""
    return t[0] + centred_mean(t - t[0], window // 2)


def judge_stamps(m: Any, path: str, t: np.ndarray, share: float,
                 again: Callable[[np.ndarray], Any]) -> None:
    """A recording whose stamps do not follow its samples (``share``, its
    :func:`stamp_share`, under :data:`STAMP_FOLLOW`) is read again by ``again`` on its
    clock ``t`` evened out (:func:`evened`): each interval of ``m`` is widened to take in
    that reading, and a value whose interval then reaches more than 20 % of itself from
    it (as for the noise, :mod:`.uncertainty`) is not to be trusted (R411, with both
    readings). ``m`` is the recording's :class:`.measured.Measured`."""
    if share >= STAMP_FOLLOW:
        return
    try:
        other_m = again(evened(t))
    except AouError:
        return

    moved = []
    for name, sp in m.uncertainty.items():
        value, other = m.descriptors.get(name), other_m.descriptors.get(name)
        if not (isinstance(value, float) and isinstance(other, float)) or \
                sp.low is None or sp.high is None or sp.low <= other <= sp.high:
            continue
        wide = replace(sp, low=min(sp.low, other), high=max(sp.high, other))
        if sp.stable and vague(name, value, wide):
            wide = replace(wide, stable=False)
            moved.append((name, value, other))
        m.uncertainty[name] = wide
    if moved:
        m.diagnostics.append(diag(
            R411, _clock(t, f", the positions' steps follow {max(share, 0.0):.0%} of that")
            + ": read on the clock evened out, "
            + "; ".join(f"{n} reads {o:.4g} instead of {v:.4g}" for n, v, o in moved)
            + f". {'These are' if len(moved) > 1 else 'This is'} not to be trusted",
            Span.whole_file(path), hint=HINT, descriptors=[n for n, _, _ in moved],
            share=share))


def stamped_on_arrival(t: np.ndarray, q: np.ndarray, noise: np.ndarray) -> bool:
    """Whether a clock's stamps do not follow its samples (:func:`stamp_share`)."""
    share = stamp_share(t, q, noise)
    return share is not None and share < STAMP_FOLLOW


def read_on_evened(m: Any, path: str, t: np.ndarray, error: AouError) -> None:
    """Say that ``m`` was read on the clock evened out, because on the recording's own
    clock, stamped on arrival, the reading contradicted the joints (``error``, an
    R406): R411 names both, and every peak acceleration ``m`` reads is not to be
    trusted (its stamps moved it once already)."""
    names = [n for n, d in every_named().items()
             if d.key == "peak_acceleration" and not d.is_count
             and isinstance(m.descriptors.get(n), float)]
    for n in names:
        if n in m.uncertainty:
            m.uncertainty[n] = replace(m.uncertainty[n], stable=False)
    first = error.diagnostics[0]
    m.diagnostics.append(diag(
        R411, _clock(t) + f", and on them the measurement failed ({first.code}: "
        f"{first.message}); read on the clock evened out instead: "
        + "; ".join(f"{n} reads {m.descriptors.get(n):.4g}" for n in names)
        + ". Values read from the evened clock are not to be trusted",
        Span.whole_file(path), hint=HINT, descriptors=names, own_clock_error=first.code))


#: What to do about a clock stamped on arrival.
HINT = "log the time each sample was taken (the controller's own stamp), not the time it " \
    "arrived"


def _clock(t: np.ndarray, follow: str = "") -> str:
    """The start of R411's text for a clock ``t`` stamped on arrival: how its steps vary,
    then ``follow`` (how far the positions follow them) inside the brackets."""
    dt = np.diff(t)
    return (f"the clock's stamps do not follow the samples (their steps vary by "
            f"{float(np.std(dt)) * 1e3:.2g} ms about {float(np.median(dt)) * 1e3:.2g} ms"
            f"{follow}: stamps taken on arrival)")
