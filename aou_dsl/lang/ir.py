"""The intermediate representation: a validated behaviour, in SI units, every node spanned.

The primitive nodes live with their kinds in :mod:`aou_dsl.lang.primitives`.

Every node is a frozen dataclass, built by keyword only: an unknown field is a TypeError,
a value of the wrong type or out of range a TypeError or ValueError naming the field
(numbers are stored as floats). The validator is what reports a file's mistakes, with
their lines; these checks guard the Python API, where nodes are built or changed
(:meth:`Node.replace`) by code. Angles are in radians, angular speeds in rad/s. Values a
file leaves out are filled from :data:`DEFAULTS` by the validator, so later stages never
guess.
"""

from __future__ import annotations

import dataclasses
import enum
import math
import types
import typing
from collections.abc import Hashable
from dataclasses import dataclass, field
from typing import Any, Literal

from ..core.diagnostics import Span
from ..core.memo import cached

__all__ = ["DEFAULTS", "Behaviour", "Effort", "Model", "Node", "Settings", "State"]


class State(enum.StrEnum):
    """The five canonical states (docs/model.md), in their table's order (ties break by it)."""

    CONFIDENT = "confident"
    CURIOUS = "curious"
    HESITANT = "hesitant"
    FEARFUL = "fearful"
    INACTIVE = "inactive"


#: Documented defaults for everything a file may leave out (docs/language.md).
DEFAULTS = {
    "start": 0.30,  # m
    "standoff": 0.10,  # m
    "approach_a": 0.10,  # m/s^2
    "retreat_a": 0.10,  # m/s^2
    "speed_cap": 0.25,  # m/s, approach and retreat (ISO/TS 15066 "reduced speed")
    "gaze_v": math.radians(20.0),  # rad/s
    "tilt_v": math.radians(20.0),  # rad/s
    # 6 deg peak to peak at 2.5 Hz needs ~13 rad/s^2 on the shivering joint: within the
    # Panda's 20 rad/s^2 on joint 7. Faster tremors need smaller amplitudes.
    "shiver_f": 2.5,  # Hz
    "shiver_duration": 1.0,  # s
}


def _check(obj: Any, name: str, value: Any, hint: Any) -> Any:
    """``value`` as field ``name`` of ``obj`` declared ``hint`` stores it, or an error."""
    if type(hint) is type and hint is not float and hint is not int \
            and isinstance(value, hint):
        return value  # a plain class, already of it (the IR's nodes in a tuple): as below
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin in (types.UnionType, typing.Union):
        if value is None and type(None) in args:
            return None
        (hint,) = [a for a in args if a is not type(None)]
        return _check(obj, name, value, hint)
    if origin is Literal:
        if value in args:
            return value
        raise ValueError(f"{type(obj).__name__}.{name}: {value!r} is not one of {args}")
    if hint is float and isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    if origin is tuple and isinstance(value, tuple | list):
        each = args[:1] * len(value) if args[-1:] == (Ellipsis,) else args
        if len(each) == len(value):
            return tuple(_check(obj, name, v, h) for v, h in zip(value, each, strict=True))
    if isinstance(hint, type) and issubclass(hint, enum.Enum) and value in set(hint):
        return hint(value)
    want = origin or hint
    if isinstance(value, want) and not (want is int and isinstance(value, bool)):
        return value
    raise TypeError(f"{type(obj).__name__}.{name}: expected {getattr(hint, '__name__', hint)}"
                    f", got {value!r}")


@cached(maxsize=512)
def _hints(cls: Any) -> dict[str, Any]:
    """The type hints of an IR class, resolved once per class."""
    return typing.get_type_hints(cls)


@dataclass(frozen=True, kw_only=True, slots=True)
class Model:
    """What every IR class shares: its fields checked when built, :meth:`replace`."""

    def __post_init__(self) -> None:
        cls = type(self)
        hints = _hints(typing.cast(Hashable, cls))  # a class is hashable
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            checked = _check(self, f.name, value, hints[f.name])
            if checked is not value:
                object.__setattr__(self, f.name, checked)

    def replace(self, **changes: Any) -> Any:
        """A copy with ``changes``, checked like a new one (typed ``Any``: the copy is of
        the object's own class)."""
        return dataclasses.replace(self, **changes)


@dataclass(frozen=True, kw_only=True, slots=True)
class Node(Model):
    """An IR node: frozen, built by keyword, spanned. Primitive nodes (one per kind, in
    :mod:`aou_dsl.lang.primitives`) add ``kind`` and ``count``."""

    span: Span
    kind: str = ""
    count: int = 1


@dataclass(frozen=True, kw_only=True, slots=True)
class Effort(Node):
    """The Laban Effort vector (docs/model.md), each factor in [-1, 1]."""

    W: float
    T: float
    S: float
    F: float

    def __post_init__(self) -> None:
        super(Effort, self).__post_init__()
        for name in "WTSF":
            if not -1.0 <= getattr(self, name) <= 1.0:
                raise ValueError(f"Effort.{name}: {getattr(self, name)} is outside [-1, 1]")


@dataclass(frozen=True, kw_only=True, slots=True)
class Settings(Model):
    """The file's settings with defaults filled in; ``spans`` holds the written ones."""

    robot: str = "panda"
    goal: tuple[float, float, float] | None = None  # None: the robot's default
    start_direction: tuple[float, float, float] | None = None  # unit vector or None
    start: float = DEFAULTS["start"]
    standoff: float = DEFAULTS["standoff"]
    effort: Effort | None = None
    spans: dict[str, Span] = field(default_factory=dict)


@dataclass(frozen=True, kw_only=True, slots=True)
class Behaviour(Model):
    """One validated ``.aou`` file."""

    name: str
    state: State | None
    form: Literal["descriptor", "sequence"]
    settings: Settings
    primitives: tuple[Node, ...]
    span: Span
    header_span: Span | None = None

    def first(self, kind: str, plane: str | None = None) -> Any:
        """The descriptor-form node of ``kind`` (and gaze ``plane``), if present. Typed
        ``Any``: the node class is the kind's (:mod:`aou_dsl.lang.primitives`)."""
        for p in self.primitives:
            if p.kind == kind and (plane is None or getattr(p, "plane", None) == plane):
                return p
        return None
