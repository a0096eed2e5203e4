"""The timeline: what the layout makes of a behaviour, and what the compiler follows.

An :class:`Episode` moves the end-effector between two :class:`Pose` s of the reach,
written in goal-centred coordinates. Pure data, no numerical imports.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.diagnostics import Span
from .ir import State

__all__ = ["Episode", "Pose", "Timeline"]


@dataclass(frozen=True, slots=True)
class Pose:
    """A pose of the reach in goal-centred coordinates.

    Attributes:
        d: distance from the goal [m].
        h: angle of the goal vector from the initial line of sight, projected into the
            horizontal plane (the plane normal to the start pose's y axis) [rad].
        v: the same in the vertical plane (normal to the start pose's x axis) [rad].
        roll: roll about the forward axis from the start pose [rad].
    """

    d: float
    h: float = 0.0
    v: float = 0.0
    roll: float = 0.0

    def lerp(self, other: Pose, f: float) -> Pose:
        """The pose a fraction ``f`` of the way to ``other``."""
        return Pose(self.d + f * (other.d - self.d), self.h + f * (other.h - self.h),
                    self.v + f * (other.v - self.v),
                    self.roll + f * (other.roll - self.roll))


@dataclass(frozen=True, slots=True)
class Episode:
    """One primitive episode of the timeline.

    ``a`` and ``vmax`` bound the episode's own path coordinate: metres for approach and
    retreat, radians for gaze (plane angle) and tilt (roll). ``duration`` [s] is fixed
    for pauses, shivers and tilts, and planned (rest to rest at ``a`` and ``vmax``) for
    the others. ``kind`` is what the episode does: an ``approach`` statement that moves
    away from the goal makes a ``retreat`` episode.
    """

    kind: str
    span: Span
    start: Pose
    end: Pose
    duration: float
    a: float = 0.0
    vmax: float = 0.0
    amplitude: float = 0.0  # shiver, peak to peak [rad]
    f: float = 0.0  # shiver [Hz]
    plane: str | None = None  # gaze

    @property
    def moving(self) -> bool:
        """Whether anything moves in it. An episode that keeps its pose, with no
        acceleration and no oscillation, is held still (a pause, or a plugin kind's
        held episode); every other kind's episode moves (its acceleration, its roll or
        its swing is never zero: validation refuses zero)."""
        return not (self.start == self.end and self.a == 0.0 and self.amplitude == 0.0
                    and self.f == 0.0)

    @property
    def path_length(self) -> float:
        """Length of the episode's path coordinate [m or rad]."""
        s, e = self.start, self.end
        return (abs(e.d - s.d) + abs(e.h - s.h) + abs(e.v - s.v)
                + abs(e.roll - s.roll))


@dataclass(frozen=True, slots=True)
class Timeline:
    """A behaviour laid out: its episodes in time order and the state that ordered them."""

    behaviour: str
    state: State
    declared_state: State | None
    episodes: tuple[Episode, ...]

    @property
    def planned_duration(self) -> float:
        return sum(e.duration for e in self.episodes)
