"""Motions the recording cuts short: an approach or a retreat under way at the
recording's first or last sample.

The part of a motion before the first sample or after the last is not in the recording,
and a phase cut there is left out of its peak acceleration (:mod:`.surges`). When the
hand still moves at :data:`CUT` of its top speed in the recording or more where the
recording cuts it,
most of that phase is missing (a stop the take cuts has not yet shed a fifth of its
speed), and its acceleration, which may be the motion's peak, is unknown: the peak read
from what the recording holds is then not a measurement. R411 says so and names the
peak acceleration it affects, which a verdict then reads as inconclusive.

The hand's speed here is its displacement over :data:`SPAN` [s] divided by that time,
in three dimensions: a velocity filter's value at the recording's very edge is a guess
(it extrapolates), a displacement is not.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..core.codes import R411
from ..core.diagnostics import Span, diag
from ..lang.descriptors import EpisodeValues
from .episodes import Context, Piece
from .recognisers import every_named

__all__ = ["CUT", "Cut", "cut_motion", "judge_cuts"]

#: A motion cut while the hand still moves at this share of its top speed or more has
#: lost most of the phase it was in.
CUT = 0.8
#: The hand's speed is read as its displacement over this long [s].
SPAN = 0.05


@dataclass(frozen=True)
class Cut:
    """An episode of ``kind`` the recording cuts at time ``at`` [s from its first
    sample], where the hand still moved at ``share`` of its top speed."""

    kind: str
    at: float
    share: float


def cut_motion(c: Context, p: Piece, e: EpisodeValues) -> Cut | None:
    """The cut of the translation ``e`` read from piece ``p``: None when both its ends
    are where the arm was at rest, or the hand moved slower than :data:`CUT` of its
    top speed in the recording where the recording cuts it (a short motion at the
    end of a long one is judged by the whole: its own top is no measure of a cut)."""
    if p.at_rest0 and p.at_rest1:
        return None
    w = max(1, int(round(SPAN / c.rest.h)))
    if len(c.pos) <= 2 * w:
        return None
    speed = np.linalg.norm(c.pos[w:] - c.pos[:-w], axis=1) / (w * c.rest.h)
    top = max(float(speed.max()), 1e-300)
    ends = [(float(speed[k]) / top, t) for k, t, rest in
            ((0, p.t0, p.at_rest0), (-1, p.t1, p.at_rest1)) if not rest]
    share, at = max(ends)
    return Cut(e.kind, at, share) if share >= CUT else None


def judge_cuts(m: Any, path: str, cuts: list[Cut]) -> None:
    """Mark the peak accelerations of the motions in ``cuts`` not to be trusted in
    ``m`` (a :class:`.measured.Measured`), with R411 naming them and where the cut is."""
    named: list[tuple[str, Cut]] = []
    for cut in cuts:
        for name, d in every_named().items():
            if d.kind != cut.kind or d.key != "peak_acceleration" or d.is_count or \
                    m.descriptors.get(name) is None or name in (n for n, _ in named):
                continue
            if name in m.uncertainty:
                m.uncertainty[name] = replace(m.uncertainty[name], stable=False)
            named.append((name, cut))
    if not named:
        return
    m.diagnostics.append(diag(
        R411, "the recording cuts a motion short: " + "; ".join(
            f"{name} {m.descriptors.get(name):.4g} is read from the {cut.kind} whose hand "
            f"still moved at {cut.share:.0%} of its top speed at t="
            f"{cut.at + m.t_origin:.3f}s, where the recording "
            f"{'ends' if cut.at > 0 else 'starts'}: most of that phase, and perhaps the "
            "peak, is not in it" for name, cut in named)
        + f". {'These are' if len(named) > 1 else 'This is'} not to be trusted",
        Span.whole_file(path),
        hint="log from rest to rest: start before the motion and stop after it",
        descriptors=[n for n, _ in named], cut_at=[c.at for _, c in named]))
