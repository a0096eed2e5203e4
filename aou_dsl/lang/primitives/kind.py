"""What every primitive kind provides, and the language-wide visibility bounds.

A kind is one object (a :class:`Kind` subclass, one module each) that knows its
statement's keys and units, how to read it from the syntax tree, how to lay one episode
of it out, the values that episode shows (for the descriptors), the evidence it gives
the C-V inference, and how to print it back as source. Pure Python.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from ...core.units import Dim
from ..ir import Node
from ..move_profile import bang_time
from ..timeline import Episode, Pose

if TYPE_CHECKING:
    from ..values import Reader

__all__ = ["MIN_ANGLE", "MIN_PAUSE", "MIN_RETREAT", "Key", "Kind", "fmt", "move"]

#: Shortest pause [s] that can be told apart from the stop between two episodes.
MIN_PAUSE = 0.2
#: Smallest angle [rad] and retreat [m] a behaviour may ask for: below, nobody sees it
#: and it cannot be measured (angles to 0.5 deg, distances to 1 mm).
MIN_ANGLE = math.radians(1.0)
MIN_RETREAT = 0.005


@dataclass(frozen=True, slots=True)
class Key:
    """A ``key=value`` argument: its dimension and the unit a bare value takes."""

    dim: Dim
    bare_unit: str
    what: str


class Kind:
    """One primitive kind. Subclasses set the class attributes and the methods."""

    #: The statement keyword (``approach``) and the IR node class it reads into.
    name: ClassVar[str]
    node: ClassVar[type[Node]]
    #: Usage line shown in diagnostics.
    usage: ClassVar[str]
    #: The ``key=`` arguments it takes.
    keys: ClassVar[Mapping[str, Key]] = {}
    #: How the compiler times its episodes: ``hold`` (a pause), ``oscillation`` (a
    #: shiver), ``fixed`` (a set duration), ``optimal`` (fastest under the limits).
    timing: ClassVar[str] = "optimal"
    #: Its path coordinate is a distance along the line of sight [m] (else an angle).
    translation: ClassVar[bool] = False
    #: C-V evidence: channel -> (episode value key, "sum" or "max").
    evidence: ClassVar[Mapping[str, tuple[str, str]]] = {}

    def read(self, r: Reader) -> Node | None:
        """The statement's node, or None after reporting what does not fit."""
        raise NotImplementedError

    def values(self, node: Node) -> dict[str, float]:
        """The values one episode of ``node`` shows, as the descriptor form declares
        them (before any layout)."""
        raise NotImplementedError

    def episode_values(self, ep: Episode) -> dict[str, float]:
        """The values a laid-out episode shows."""
        raise NotImplementedError

    def format(self, node: Node) -> str:
        """A descriptor-form statement that validates back to ``node``."""
        raise NotImplementedError


def fmt(x: float) -> str:
    """A number as source text: six significant digits, no trailing zeros."""
    return f"{x:.6g}"


def repeat(count: int) -> str:
    return f" x{count}" if count != 1 else ""


def move(kind: str, span, start: Pose, end: Pose, a: float, vmax: float,
         **extra) -> Episode:
    """A rest-to-rest episode timed at peak acceleration ``a`` and speed cap ``vmax``."""
    ep = Episode(kind, span, start, end, 0.0, a=a, vmax=vmax, **extra)
    return Episode(kind, span, start, end, bang_time(ep.path_length, a, vmax), a=a,
                   vmax=vmax, **extra)
