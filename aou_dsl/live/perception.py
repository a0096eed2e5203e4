"""What the robot sees, as the regulator reads it: an estimate of the target with a
confidence and the evidence behind it.

A perception is anything that, asked at a controller tick ``t`` [s], answers with an
:class:`Estimate`: where it thinks the target is, how sure it is (a confidence in [0, 1])
and the evidence that made it (a small frozen record, :class:`Evidence`). aou ships two
(:mod:`.geometric`, a model of what a camera would see, and :mod:`.camera`, a rendered
camera with a fiducial detector); a user's own detector plugs in as

- a callable ``f(t) -> Estimate`` (or ``-> (position, confidence)``, or ``-> confidence``),
- or an object with a method ``perceive(t)`` answering the same.

:func:`as_perception` makes any of those a :class:`Perception`. The regulator takes
``uncertainty = 1 - confidence`` (:func:`uncertainty_of`), applies its hysteresis and maps
it to a state and an intensity (:func:`aou_dsl.live.regulator.from_uncertainty`).
docs/live.md has an example.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol, runtime_checkable

from ..core.codes import I504
from ..core.diagnostics import AouError, Span, diag

__all__ = ["Estimate", "Evidence", "Perception", "as_perception", "uncertainty_of"]

_WHERE = Span.whole_file("<perception>")


@dataclass(frozen=True)
class Evidence:
    """Why a perception is as confident as it says: the named signals it fused (each a
    number, e.g. ``visible``, ``size_px``, ``blur_px``, ``margin``), and its source."""

    source: str = "user"
    signals: tuple[tuple[str, float], ...] = ()

    def get(self, name: str, default: float | None = None) -> float | None:
        """The signal ``name`` (or ``default``)."""
        return dict(self.signals).get(name, default)

    def to_json(self) -> dict[str, Any]:
        return {"source": self.source, **{k: _rounded(v) for k, v in self.signals}}


@dataclass(frozen=True)
class Estimate:
    """One answer of a perception.

    Attributes:
        confidence: how sure it is that it sees the target, in [0, 1].
        position: the target's estimated position [m] (None when it has no estimate).
        evidence: the signals behind the confidence.
    """

    confidence: float
    position: tuple[float, float, float] | None = None
    evidence: Evidence = field(default_factory=Evidence)

    def __post_init__(self) -> None:
        c = self.confidence
        if isinstance(c, bool) or not isinstance(c, int | float) or not 0.0 <= c <= 1.0:
            raise AouError(diag(I504, f"a perception's confidence must be a number in "
                                f"[0, 1], found {c!r:.40}", _WHERE))
        if self.position is not None:
            p = self.position
            if (not isinstance(p, tuple | list) or len(p) != 3
                    or not all(isinstance(x, int | float) and math.isfinite(x) for x in p)):
                raise AouError(diag(I504, f"a perception's position must be three finite "
                                    f"numbers [m], found {p!r:.60}", _WHERE))
            object.__setattr__(self, "position", tuple(float(x) for x in p))
        object.__setattr__(self, "confidence", float(c))


@runtime_checkable
class Perception(Protocol):
    """Anything with ``perceive(t) -> Estimate``."""

    def perceive(self, t: float) -> Estimate: ...


class _Called:
    """A callable made a :class:`Perception`."""

    def __init__(self, f: Callable[[float], Any]):
        self.f = f

    def perceive(self, t: float) -> Estimate:
        return _estimate(self.f(t))


class _Method:
    """An object whose ``perceive`` may answer with a bare confidence or a pair."""

    def __init__(self, obj: Any):
        self.obj = obj

    def perceive(self, t: float) -> Estimate:
        return _estimate(self.obj.perceive(t))


def _estimate(answer: Any) -> Estimate:
    """An :class:`Estimate` from what a user's perception answered."""
    if isinstance(answer, Estimate):
        return answer
    if isinstance(answer, int | float) and not isinstance(answer, bool):
        return Estimate(float(answer))
    if isinstance(answer, tuple) and len(answer) == 2:
        position, confidence = answer
        return Estimate(confidence, None if position is None else tuple(position))
    raise AouError(diag(I504, f"a perception must answer with an Estimate, a confidence "
                        f"in [0, 1] or a (position, confidence) pair; found {answer!r:.60}",
                        _WHERE))


def as_perception(obj: Any) -> Perception:
    """``obj`` as a :class:`Perception`: an object with a ``perceive(t)`` method, or a
    callable of ``t``.

    Raises:
        AouError: I504 when it is neither.
    """
    if callable(getattr(obj, "perceive", None)):
        return obj if isinstance(obj, _Called | _Method) else _Method(obj)
    if callable(obj):
        return _Called(obj)
    raise AouError(diag(I504, f"a perception is a callable of the time or an object with a "
                        f"`perceive(t)` method; found {type(obj).__name__}", _WHERE))


def uncertainty_of(estimate: Estimate) -> float:
    """What the regulator takes: ``1 - confidence``."""
    return min(1.0, max(0.0, 1.0 - estimate.confidence))


def _rounded(x: float) -> float:
    return float(f"{x:.6g}")
