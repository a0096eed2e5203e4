"""The ``measure`` part: finding anticipations in a measured motion.

aou's measurement reads every move along the line of sight as an approach (it ends
closer to the goal) or a retreat (further). An anticipation is a retreat of at most
:data:`~.kind.MAX_DISTANCE` that an approach follows at once, with no pause between
them: :meth:`Recognise.claim` relabels each such retreat as an anticipation, keeping the
values the measurement read (its ``distance`` [m] and ``peak_acceleration`` [m/s^2]).
A retreat with a pause after it stays a retreat, and so does a larger move away.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from aou_dsl.lang.descriptors import EpisodeValues
from aou_dsl.lang.primitives import APPROACH, RETREAT

from .kind import MAX_DISTANCE, NAME

__all__ = ["SLACK", "Recognise"]

#: How far a measured draw-back may pass :data:`MAX_DISTANCE` and still be read as one
#: [m]: the measurement reads distances to the millimetre.
SLACK = 1e-3


class Recognise:
    """A pass over the measured episodes that claims the anticipations."""

    def claim(self, episodes: Sequence[EpisodeValues]) -> list[EpisodeValues]:
        out = list(episodes)
        for i, e in enumerate(out[:-1]):
            if e.kind == RETREAT and out[i + 1].kind == APPROACH and \
                    e.values.get("distance", 0.0) <= MAX_DISTANCE + SLACK:
                out[i] = replace(e, kind=NAME)
        return out
