"""What every primitive kind provides, and the language-wide visibility bounds.

A kind is one object (a :class:`Kind` subclass, one module each) that knows its
statement's keys and units, how to read it from the syntax tree, how to lay one episode
of it out, the values that episode shows (for the descriptors), the evidence it gives
the C-V inference, and how to print it back as source. Pure Python.
"""

from __future__ import annotations

import abc
import enum
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

from ...core.units import Dim
from ..ir import Node
from ..move_profile import bang_time
from ..timeline import Episode, Pose

if TYPE_CHECKING:
    from ..values import Reader

__all__ = ["MIN_ANGLE", "MIN_PAUSE", "MIN_RETREAT", "Key", "Kind", "Needs", "Timing", "fmt",
           "given", "move"]

#: How much a measured value may miss an invariant's bound before it counts as broken:
#: a measurement reads a frequency from a few swings, to a few per cent.
LOOK_SLACK = 0.05

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


class Timing(enum.Enum):
    """How the compiler times a kind's episodes."""

    #: Held still for the episode's duration (a pause).
    HOLD = "hold"
    #: A periodic swing of one joint, its frequency and cycles given (a shiver).
    OSCILLATION = "oscillation"
    #: A path run in the duration the layout set (a tilt at its declared speed).
    FIXED = "fixed"
    #: The fastest run of the path under the arm's limits and the declared peak
    #: acceleration (approach, retreat, gaze).
    OPTIMAL = "optimal"


def _a(word: str) -> str:
    return f"{'an' if word[:1] in 'aeiou' else 'a'} {word}"


@dataclass(frozen=True, slots=True)
class Needs:
    """What an episode of a kind needs around it to count (to show its descriptors), and
    so where a layout may put it. Kinds are named by their keywords.

    Attributes:
        preceded_by: the kind of the episode that must end right before it (a retreat
            starts at a pause), or None.
        followed_by: the kind of the episode that must start right after it, nothing
            between (a retreat ends at a pause, a gaze's angle is read at the pause that
            ends it; a counter-movement that anticipates an approach comes directly
            before one), or None.
        apart: two of its episodes never touch: motion goes between them (two pauses in
            a row are seen and measured as one hold).
    """

    preceded_by: str | None = None
    followed_by: str | None = None
    apart: bool = False

    def met(self, before: str | None, after: str | None) -> bool:
        """Whether an episode counts between an episode of kind ``before`` and one of
        kind ``after`` (None: the timeline's start or end)."""
        return ((self.preceded_by is None or before == self.preceded_by)
                and (self.followed_by is None or after == self.followed_by))

    @property
    def around(self) -> tuple[str, ...]:
        """The kinds it needs next to it, one entry per neighbour (before, then after)."""
        return tuple(k for k in (self.preceded_by, self.followed_by) if k is not None)

    def words(self, name: str, hold: str) -> str | None:
        """What an episode of kind ``name`` needs, as a sentence after its name (``hold``:
        the keyword of the kind that ends a motion, whose end reads its value); None
        when it counts anywhere."""
        p, f = self.preceded_by, self.followed_by
        if p is not None and p == f:
            return f"{_a(name)} counts only between two {p}s, one before and one after it"
        if p is not None and f is not None:
            return f"{_a(name)} counts only right after {_a(p)} and right before {_a(f)}"
        if f == hold:
            return f"{_a(name)} counts only when {_a(f)} ends it"
        if f is not None:
            return f"{_a(name)} counts only directly before {_a(f)}, nothing between"
        if p is not None:
            return f"{_a(name)} counts only right after {_a(p)}"
        return None


class Kind(abc.ABC):
    """One primitive kind: the contract a new kind implements. Subclasses set the class
    attributes ``name``, ``node``, ``usage`` and ``evidence`` (checked when the subclass is
    made) and implement the abstract methods (checked when it is instantiated)."""

    _REQUIRED: ClassVar[tuple[str, ...]] = ("name", "node", "usage", "evidence")

    #: The statement keyword (``approach``) and the IR node class it reads into.
    name: ClassVar[str]
    node: ClassVar[type[Node]]
    #: Usage line shown in diagnostics.
    usage: ClassVar[str]
    #: The ``key=`` arguments it takes.
    keys: ClassVar[Mapping[str, Key]] = {}
    #: How the compiler times its episodes.
    timing: ClassVar[Timing] = Timing.OPTIMAL
    #: Its path coordinate is a distance along the line of sight [m] (else an angle).
    translation: ClassVar[bool] = False
    #: C-V evidence: channel -> (episode value key, "sum" or "max").
    evidence: ClassVar[Mapping[str, tuple[str, str]]]
    #: What makes its episodes look like this kind to a person, in words: the invariant
    #: :meth:`keeps_look` holds a fit to and :meth:`reads_as` reads a measured episode by.
    look: ClassVar[str] = ""
    #: What its episodes need around them to count, and so where a layout may put them
    #: (:class:`Needs`): none by default. A plugin kind sets its own, e.g.
    #: ``needs = Needs(followed_by=APPROACH)`` for a move directly before an approach.
    needs: ClassVar[Needs] = Needs()

    def __init_subclass__(cls, **kw) -> None:
        super().__init_subclass__(**kw)
        missing = [a for a in Kind._REQUIRED if not hasattr(cls, a)]
        if missing:
            raise TypeError(f"primitive kind {cls.__name__} does not set {', '.join(missing)}")

    @abc.abstractmethod
    def read(self, r: Reader) -> Node | None:
        """The statement's node, or None after reporting what does not fit."""

    @abc.abstractmethod
    def episode(self, node: Any, pose: Pose, arg: float | None = None) -> Episode:
        """One episode of ``node`` from ``pose``. ``arg`` is where it goes when the
        layout decides it: the distance to the goal an approach ends at [m], the plane
        angle a gaze turns to or the roll a tilt turns by [rad]; other kinds take none."""

    @abc.abstractmethod
    def values(self, node: Any) -> dict[str, float]:
        """The values one episode of ``node`` shows, as the descriptor form declares
        them (before any layout)."""

    @abc.abstractmethod
    def episode_values(self, ep: Episode) -> dict[str, float]:
        """The values a laid-out episode shows."""

    @abc.abstractmethod
    def format(self, node: Any) -> str:
        """A descriptor-form statement that validates back to ``node``."""

    def keeps_look(self, declared: Episode, fitted: Episode) -> str | None:
        """None when ``fitted`` (an episode of this kind as a fit changed it) still looks
        like ``declared`` did, else what it would look like instead, in words. Here: it
        is still of this kind (a subclass adds its own invariant)."""
        if fitted.kind != declared.kind:
            return f"it would be a {fitted.kind}, not a {declared.kind}"
        return None

    def reads_as(self, kind_values: Mapping[str, float], duration: float) -> str:
        """The kind a person reads a measured episode of this kind as (its ``values`` and
        its ``duration`` [s]): this kind, unless a subclass's invariant says otherwise."""
        return self.name


def given(arg: float | None, what: str) -> float:
    """The layout's argument of an episode that needs one."""
    if arg is None:
        raise ValueError(f"{what} is the layout's to give")
    return arg


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
