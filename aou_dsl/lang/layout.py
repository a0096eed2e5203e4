"""Layout: a behaviour -> a timeline of episodes (pure Python, no heavy imports).

A sequence is laid out as written. The descriptor form is laid out in stops, the state's
order, an approach split between them and pauses in the gaps, searched until an
arrangement shows every descriptor the file writes: :mod:`.stops` has the rules
(docs/compiler.md has them with a table per state).
"""

from __future__ import annotations

import struct

from .cv import composition, infer
from .descriptors import EpisodeValues
from .ir import Behaviour, Node
from .kind_needs import episode_values
from .primitives import KINDS, SHIVER, Approach, Gaze, Tilt
from .stops import STOP_ORDER, descriptor_layout
from .timeline import Episode, Pose, Timeline

__all__ = ["STOP_ORDER", "Laid", "episode_values", "layout", "nominal_values"]

# --- the sequence form ----------------------------------------------------------------------


class Laid:
    """The episodes each statement of a sequence was laid out into, and from which pose:
    a layout of the same file after an edit takes them again for a statement whose node
    (the same object: kept by the incremental linter) starts from the same pose. What
    one layout did not use is forgotten by the next (:meth:`turn`)."""

    def __init__(self) -> None:
        self._last: dict[int, tuple] = {}
        self._now: dict[int, tuple] = {}

    def turn(self) -> None:
        self._last, self._now = self._now, {}

    @staticmethod
    def _where(pose: Pose, standoff: float) -> bytes:
        """The pose and standoff to the bit (``==`` would take -0.0 for 0.0)."""
        return struct.pack("5d", pose.d, pose.h, pose.v, pose.roll, standoff)

    def get(self, p: Node, pose: Pose, standoff: float) -> tuple[list[Episode], Pose] | None:
        e = self._now.get(id(p)) or self._last.get(id(p))
        if e is None or e[0] is not p or e[1] != self._where(pose, standoff):
            return None
        self._now[id(p)] = e
        return e[2], e[3]

    def put(self, p: Node, pose: Pose, standoff: float, eps: list[Episode], end: Pose
            ) -> None:
        # p is held, so that its id stays its own while kept
        self._now[id(p)] = (p, self._where(pose, standoff), eps, end)


def _sequence(b: Behaviour, laid: Laid | None = None) -> list[Episode]:
    s = b.settings
    pose = Pose(s.start)
    out: list[Episode] = []
    for p in b.primitives:
        kept = laid.get(p, pose, s.standoff) if laid is not None else None
        if kept is not None:
            out += kept[0]
            pose = kept[1]
            continue
        start, eps = pose, []
        for _ in range(p.count):
            ep = _sequence_episode(p, pose, s.standoff)
            if ep.moving and ep.path_length == 0.0 and ep.kind != SHIVER:
                continue  # nothing moves (e.g. an approach already at the standoff)
            eps.append(ep)
            pose = ep.end
        out += eps
        if laid is not None:
            laid.put(p, start, s.standoff, eps, pose)
    return out


def _sequence_episode(p: Node, pose: Pose, standoff: float) -> Episode:
    arg: float | None = None
    if isinstance(p, Approach):
        arg = standoff if p.length is None else pose.d - p.length
    elif isinstance(p, (Gaze, Tilt)):  # to a plane angle, by a roll: as written
        arg = p.angle
    return KINDS[p.kind].episode(p, pose, arg)


# --- values for the descriptors and the C-V inference ------------------------------------


def nominal_values(b: Behaviour) -> list[EpisodeValues]:
    """A descriptor-form file's episodes as written, before any layout: ``count`` copies of
    each statement's values (for the C-V inference, which needs no order)."""
    return [EpisodeValues(p.kind, values=KINDS[p.kind].values(p))
            for p in b.primitives for _ in range(p.count)]


def layout(b: Behaviour, laid: Laid | None = None) -> Timeline:
    """Lay a behaviour out in time. Deterministic: the same IR gives the same timeline.

    A file without a declared state is laid out as the state its primitives express.
    ``laid`` keeps a sequence's episodes for the next layout of the same file.
    """
    if b.form == "sequence":
        episodes = _sequence(b, laid)
        state = b.state or infer(composition(episode_values(episodes)))[0].state
    else:
        state = b.state or infer(composition(nominal_values(b)))[0].state
        episodes = descriptor_layout(b, state)
    return Timeline(b.name, state, b.state, tuple(episodes))
