"""The path through the Commitment-Vigilance plane a rising uncertainty walks, and how far
an estimate must move along it before the expressed behaviour changes (the
:class:`.regulator.Regulator`'s hysteresis, sized from the camera's confidence noise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..core.codes import I504
from ..core.diagnostics import AouError, Span, diag
from ..lang.cv import CANONICAL
from ..lang.ir import State

__all__ = ["CONFIDENCE_NOISE", "NOISE_MARGIN", "PATH", "Hysteresis", "from_uncertainty",
           "hysteresis_for", "hysteresis_margins"]

_WHERE = Span.whole_file("<live>")

#: The canonical states in order of rising uncertainty: full certainty (confident), missing
#: but wanted information (curious), threat without a resolved response (hesitant),
#: threat without coping (fearful), disengagement (inactive).
PATH = (State.CONFIDENT, State.CURIOUS, State.HESITANT, State.FEARFUL, State.INACTIVE)


def from_uncertainty(u: float) -> tuple[float, float, float]:
    """(C, V, intensity) for an uncertainty ``u`` in [0, 1].

    ``u`` walks the C-V plane along :data:`PATH` in straight legs between canonical points,
    one state every 1/4: confident at 0, curious at 0.25, hesitant at 0.5, fearful at 0.75,
    inactive at 1. The intensity is how close the point is to its state's canonical point
    along the path: 1 on it, 0 at the border between two states (1/8 away).

    Raises:
        AouError: I501 when ``u`` is not a number in [0, 1].
    """
    if not (isinstance(u, int | float) and 0.0 <= u <= 1.0):
        raise AouError(diag(I504, f"the uncertainty must be a number in [0, 1], found "
                            f"{u!r}", _WHERE))
    s = 4.0 * float(u)
    k = min(int(s), 3)
    f = s - k
    (c0, v0), (c1, v1) = CANONICAL[PATH[k]], CANONICAL[PATH[k + 1]]
    nearest = round(s)
    return c0 + f * (c1 - c0), v0 + f * (v1 - v0), max(0.0, 1.0 - 2.0 * abs(s - nearest))


#: The rendered camera's confidence noise: the largest standard deviation of its
#: confidence at a still scene, as the loop reads it, over the calibration's sweeps
#: (``tools/calibrate_perception.py --noise`` measures it, docs/perception-noise.csv).
CONFIDENCE_NOISE = 0.027
#: An estimate must pass a border by this many standard deviations of that noise.
NOISE_MARGIN = 2.0
#: The longest leg of :data:`PATH` [C-V units]: a margin there is the least uncertainty.
_LONGEST = max(math.dist(CANONICAL[a], CANONICAL[b])
               for a, b in zip(PATH, PATH[1:], strict=False))


def hysteresis_margins(sigma: float, margin: float = NOISE_MARGIN) -> tuple[float, float]:
    """(state, intensity) margins that hold an uncertainty whose noise has std ``sigma``
    ``margin`` standard deviations past a border: ``u`` past the border between two
    states by ``du`` puts the point ``8 L du`` nearer the new state's canonical point
    than the old one's (L the leg's length, the longest leg the worst), and moves the
    intensity by ``8 du``."""
    du = margin * sigma
    return round(8.0 * _LONGEST * du, 3), round(8.0 * du, 3)


_STATE, _INTENSITY = hysteresis_margins(CONFIDENCE_NOISE)


@dataclass(frozen=True)
class Hysteresis:
    """How far an estimate must move before the expressed behaviour changes. The
    defaults hold the uncertainty :data:`NOISE_MARGIN` standard deviations of the
    rendered camera's confidence noise (:data:`CONFIDENCE_NOISE`) past each border
    (:func:`hysteresis_margins`).

    Attributes:
        state: a new state is expressed once the point is this much nearer [C-V units]
            to its canonical point than to the expressed state's.
        intensity: a new intensity level is expressed once the intensity is this much
            past the midpoint between the expressed level and the next.
        uncertainty: an uncertainty signal is ignored while it stays within this of the
            last value that was used (a backlash).
    """

    state: float = _STATE
    intensity: float = _INTENSITY
    uncertainty: float = 0.05


def hysteresis_for(sigma: float, margin: float = NOISE_MARGIN) -> Hysteresis:
    """The hysteresis for a confidence whose noise has std ``sigma``
    (:func:`hysteresis_margins`; the uncertainty's backlash stays the default)."""
    state, intensity = hysteresis_margins(sigma, margin)
    return Hysteresis(state=state, intensity=intensity)
