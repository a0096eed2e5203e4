"""Episodes: the motion between the boundaries of :mod:`.holds`, classified by what moved.

- The hand translated more than :data:`STILL_TRANSLATION`, mostly along the goal vector:
  an approach (closer) or a retreat (further). Without a goal, along the hand's forward
  axis (the line of sight the model assumes).
- The hand translated around the goal: a gaze, read as the goal vector's bearing from
  its start direction in the planes fixed by the start pose.
- The hand stayed in place and turned: a roll piece, made into tilts and shivers by
  :mod:`.roll`.

Peak accelerations are read phase by phase (:mod:`.peaks`, from the hand's travel with
the joints' noise across their path removed), and checked against what the joints can
produce.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.codes import R406
from ..core.diagnostics import AouError, Span, diag
from ..lang.descriptors import EpisodeValues
from ..lang.primitives import GAZE
from ..robot.batch_fk import classical_acceleration, linear_jacobian
from ..robot.kinematics import ArmModel
from .holds import Boundary, Rest
from .peaks import episode_peak, path_travel, phase_peak
from .recognisers import moved_along
from .signal import curvature_gain, filters_at, odd, row_sum, slope_gain, smooth
from .surges import phases

__all__ = ["COMPUTED_NOISE", "STILL_TRANSLATION", "Context", "Piece", "Samples",
           "peak_acceleration", "pieces", "translation"]

#: Translation under which an episode has not moved the hand [m].
STILL_TRANSLATION = 2e-3
#: A gaze moved in a plane when its bearing there changed by more than this [deg].
MIN_GAZE_SWEEP = 0.25
#: How long an arm's own tracking transients last after each switch of the acceleration
#: [s]: a recording's acceleration is read over at least this long (never longer than
#: the phase it is read in).
TRANSIENT = 0.06
#: Joint noise [rad] up to which a trajectory was computed (aou's own, a planner's,
#: written at full precision), not recorded on an arm: it has no tracking transients.
#: Also how closely a computed trajectory's carried velocities match its positions.
COMPUTED_NOISE = 1e-7


@dataclass(frozen=True)
class Samples:
    """A recording's own samples, where its clock is not the grid's: times from its
    first sample [s] (K,), joint positions (K, n) and the hand's positions [m] (K, 3).
    Accelerations are read from them at their own times."""

    t: np.ndarray
    q: np.ndarray
    pos: np.ndarray


@dataclass(frozen=True)
class Context:
    """Everything an episode is measured from (arrays over the grid's N samples).

    Attributes:
        arm: the robot model; path: the recording, for diagnostics.
        rest: the rest test's signals (times, step, joint velocities, thresholds).
        q: joint positions on the grid, (N, n); noise: each joint's noise [rad], (n,).
        pos, pos_s: end-effector position, raw and filtered [m], (N, 3).
        rot: end-effector rotations, (N, 3, 3).
        roll: the hand's roll about its forward axis since the first sample,
            unwrapped [rad], (N,).
        goal: goal position [m] or None.
        y0, x0: the start pose's y and x axes: normals of the horizontal and vertical
            gaze planes.
        edge_rest: whether the arm is at rest at the first and at the last sample. A
            file that carries its joint velocities says so exactly (a jerk-limited start
            barely moves in its first samples, so a fit there would call it moving);
            otherwise the rest test decides.
        raw: the recording's own samples when it was put on the grid by interpolation
            (None: the grid is its own clock).
        computed: whether the trajectory was computed (aou's own, a planner's), not
            recorded on an arm: it has no tracking transients.
    """

    arm: ArmModel
    path: str
    rest: Rest
    q: np.ndarray
    noise: np.ndarray
    pos: np.ndarray
    pos_s: np.ndarray
    rot: np.ndarray
    roll: np.ndarray
    goal: np.ndarray | None
    y0: np.ndarray
    x0: np.ndarray
    edge_rest: tuple[bool, bool]
    raw: Samples | None = None
    computed: bool = False


@dataclass(frozen=True)
class Piece:
    """The motion between two boundaries: times, grid samples (inclusive), and the
    hand's position and roll at both ends (averaged over a pause where one is)."""

    t0: float
    t1: float
    i0: int
    i1: int
    p0: np.ndarray
    p1: np.ndarray
    roll0: float
    roll1: float
    at_rest0: bool  # starts where the arm was at rest (not at the recording's first sample)
    at_rest1: bool
    held0: bool = False  # starts at the end of a pause (a hold, not an instant)
    held1: bool = False


def _anchor(c: Context, b: Boundary, side: int) -> tuple[np.ndarray, float]:
    """The hand's position and roll at a boundary: the mean over a pause's inner
    samples, or the filtered value at an instant."""
    t = c.rest.t
    if b.pause:
        # The samples from t0 + a quarter to t1 less a quarter (the times increase).
        k0 = int(np.searchsorted(t, b.t0 + 0.25 * (b.t1 - b.t0), "left"))
        k1 = int(np.searchsorted(t, b.t1 - 0.25 * (b.t1 - b.t0), "right"))
        lo, hi = (k0, k1) if k1 > k0 else (b.i0, b.i1 + 1)
        # Laid out by rows as a gather of them lays them (a view of rows laid out so,
        # else a copy), not a view by columns: the mean sums in that order. Each mean is
        # NumPy's: the sum along the samples over their count.
        rows = np.ascontiguousarray(c.pos[lo:hi])
        return (np.add.reduce(rows, axis=0) / (hi - lo),
                float(np.add.reduce(np.ascontiguousarray(c.roll[lo:hi]))) / (hi - lo))
    tt = b.t0 if side < 0 else b.t1
    # Interpolated between the two samples around it, as over all of them (not copying
    # a column of the whole recording for each).
    k = int(np.searchsorted(t, tt, "right"))
    near = slice(max(k - 1, 0), k + 1)
    p = np.array([np.interp(tt, t[near], c.pos_s[near, j]) for j in range(3)])
    return p, float(np.interp(tt, t[near], c.roll[near]))


def pieces(c: Context, bounds: list[Boundary]) -> list[Piece | Boundary]:
    """The boundaries' pauses and the motion pieces between them, in time order."""
    t = c.rest.t
    n = len(t)
    out: list[Piece | Boundary] = []
    first = Boundary(float(t[0]), float(t[0]), 0, 0, False)
    last = Boundary(c.rest.t_last, c.rest.t_last, n - 1, n - 1, False)
    seq = [first, *bounds, last]
    held: dict[int, tuple[np.ndarray, float]] = {}

    def anchor(b: Boundary, side: int) -> tuple[np.ndarray, float]:
        # A pause anchors the piece before it and the one after it alike: averaged once.
        if not b.pause:
            return _anchor(c, b, side)
        if id(b) not in held:
            held[id(b)] = _anchor(c, b, side)
        return held[id(b)]

    for a, b in zip(seq[:-1], seq[1:], strict=True):
        if a.pause and a is not first:
            out.append(a)
        ta, tb = a.t1, b.t0
        i0 = int(np.searchsorted(t, ta, "left"))
        i1 = int(np.searchsorted(t, tb, "right")) - 1
        if tb - ta <= 0 or i1 - i0 < 1:
            continue
        p0, r0 = anchor(a, +1) if a is not first else (c.pos_s[0], float(c.roll[0]))
        p1, r1 = anchor(b, -1) if b is not last else (c.pos_s[-1], float(c.roll[-1]))
        rest0 = a is not first or c.edge_rest[0]
        rest1 = b is not last or c.edge_rest[1]
        out.append(Piece(ta, tb, i0, i1, p0, p1, r0, r1, rest0, rest1,
                         a.pause and a is not first, b.pause and b is not last))
    return out


def _bearing(a: np.ndarray, b: np.ndarray, normal: np.ndarray) -> float:
    """Angle from ``a`` to ``b`` about ``normal`` [deg]; both projected onto its plane."""
    a = a - (a @ normal) * normal
    b = b - (b @ normal) * normal
    return math.degrees(math.atan2(float(np.cross(a, b) @ normal), float(a @ b)))


def _length(v: np.ndarray) -> float:
    """``np.linalg.norm`` of the vector ``v``, the same number: the root of its dot
    product with itself, laid out as norm lays it (without norm's general checks, on
    the few vectors of every piece)."""
    x = v.ravel(order="K")
    return math.sqrt(float(x.dot(x)))


def translation(c: Context, p: Piece, g0: np.ndarray | None) -> EpisodeValues | None:
    """An approach, retreat or gaze; None when the hand did not translate."""
    seg = c.pos_s[p.i0:p.i1 + 1]
    off = seg - p.p0  # the largest distance is the root of the largest square
    travel = max(float(np.sqrt(row_sum(off * off).max())),
                 _length(p.p1 - p.p0))
    if travel <= STILL_TRANSLATION:
        return None
    d = p.p1 - p.p0
    if c.goal is not None:
        along = _length(c.goal - p.p1) - _length(c.goal - p.p0)
        along = -along  # positive: closer to the goal
    else:
        along = float(d @ c.rot[p.i0][:, 2])  # along the forward axis
    if abs(along) >= 0.7 * travel:
        kind = moved_along(along > 0)
        length = _length(d)
        u = d / max(length, 1e-12)
        peak, sd = peak_acceleration(c, p, u)
        return EpisodeValues(kind, p.t0, p.t1, {
            "distance": length, "peak_acceleration": peak,
            "peak_acceleration_sd": sd})
    values: dict[str, float] = {}
    if c.goal is not None and g0 is not None:
        ga, gb = c.goal - p.p0, c.goal - p.p1
        for plane, normal in (("horizontal", c.y0), ("vertical", c.x0)):
            start, end = _bearing(g0, ga, normal), _bearing(g0, gb, normal)
            if abs(end - start) > MIN_GAZE_SWEEP:
                values[plane] = abs(end)
        values["angle"] = max(values.values(), default=0.0)
    return EpisodeValues(GAZE, p.t0, p.t1, values)


def peak_acceleration(c: Context, p: Piece, u: np.ndarray) -> tuple[float, float]:
    """Peak acceleration of the hand along the direction of travel ``u`` [m/s^2], and
    the std the joints' noise gives it: each speeding-up and slowing-down phase read as
    :mod:`.peaks` explains, from the recording's own samples at their own times; in a
    recording never over less than :data:`TRANSIENT` where the phase allows (so that
    the arm's own transients at each switch average out).

    Raises:
        AouError: R406 when the joints' own accelerations cannot produce the peak.
    """
    r, h = c.rest, c.rest.h
    # A recording's travel is summed in NumPy's order (its noise is far above the
    # rounding); a computed trajectory's in the filter's one fixed order.
    speed = np.abs(smooth(c.pos[p.i0:p.i1 + 1] @ u, r.window, 1, h, order=2,
                          exact=c.computed))
    jac = linear_jacobian(c.arm, c.q[(p.i0 + p.i1) // 2])
    sigma_x = float(np.sqrt(np.sum(((u @ jac) * c.noise) ** 2)))
    src = c.raw if c.raw is not None else Samples(r.t, c.q, c.pos)
    k0 = int(np.searchsorted(src.t, p.t0 - 1e-9 * max(h, 1.0), "left"))
    k1 = int(np.searchsorted(src.t, p.t1 + 1e-9 * max(h, 1.0), "right")) - 1
    # The held sample just before a start from a pause (after a stop at one) belongs to
    # the motion's readings: at a low rate the first moving sample's acceleration needs it.
    k0 -= int(p.held0 and k0 > 0)
    k1 += int(p.held1 and k1 < len(src.t) - 1)
    t, x, q = src.t[k0:k1 + 1], src.pos[k0:k1 + 1] @ u, src.q[k0:k1 + 1]
    grid = r.t[p.i0:p.i1 + 1]
    # Read on the grid's own clock, grid sample i is read sample i + i0 - k0 (the same
    # time): where the search finds it when the sample beside it on the search's side
    # holds another time (the first of equal times, or the last).
    shift = p.i0 - k0 if c.raw is None else None

    def own(i: int, side: int) -> int:  # grid sample i of the piece, in its own samples
        if i == (0 if side < 0 else len(grid) - 1):
            return 0 if side < 0 else len(t) - 1
        j = -1 if shift is None else i + shift
        if 0 <= j < len(t) and ((j == 0 or t[j - 1] < t[j]) if side < 0
                                else (j == len(t) - 1 or t[j + 1] > t[j])):
            return j
        at = int(np.searchsorted(t, grid[i], "left" if side < 0 else "right"))
        return at if side < 0 else at - 1

    def travel(j0: int, j1: int) -> tuple[np.ndarray, float] | None:
        return path_travel(x[j0:j1 + 1], q[j0:j1 + 1], c.noise)

    transient = 0.0 if c.computed else TRANSIENT
    # An arm's transients grow with the step of its acceleration: from rest by the
    # level, where one motion reverses into the next by up to twice it.
    steps = (2.0 if p.at_rest0 and not p.held0 else 1.0,
             2.0 if p.at_rest1 and not p.held1 else 1.0)
    # At a dip between two surges the acceleration turns from slowing down to speeding up.
    # Each surge's speeding-up and slowing-down phases (:mod:`.surges`).
    runs = phases(speed, h, p.at_rest0, p.at_rest1, sigma_x * slope_gain(r.window, h))
    found = [f for ph in runs
             if (f := phase_peak(t, x, own(ph.a, -1), own(ph.b, +1), sigma_x, transient,
                                 travel if c.noise.max() > 0 else None,
                                 2.0 if ph.at_dip else steps[0] if ph.a == 0
                                 else steps[1] if ph.b == len(grid) - 1 else 1.0,
                                 (own(ph.lo, -1), own(ph.hi, +1)))) is not None]
    if not found:
        return 0.0, 0.0
    peak = episode_peak(found)
    if peak.value > 0:
        at = min(int(np.searchsorted(r.t, peak.at)), len(r.t) - 1)  # never below 0
        window = min(odd(peak.span / h), len(r.t) - (1 - len(r.t) % 2))
        _self_check(c, peak.value, at, max(window, 3), u, sigma_x, peak.sd)
    return peak.value, peak.sd


def _self_check(c: Context, peak: float, at: int, window: int, u: np.ndarray,
                sigma_x: float, sd: float = 0.0) -> None:
    """R406 when the joint motion around sample ``at`` cannot produce ``peak`` (whose
    std from the noise is ``sd``): the hand's acceleration there is ``J qdd + Jdot qd``
    from the joints' filtered velocities and accelerations over the same window."""
    n, h = len(c.rest.t), c.rest.h
    half = window // 2
    near = np.array(_five(at, half, n))
    q = c.q[near]
    qd, qdd = filters_at(c.q, window, (1, 2), h, near)
    joint_side = classical_acceleration(c.arm, q, qd, qdd) @ u
    noise = max(sd, sigma_x * curvature_gain(window, h))
    bound = 1.25 * float(np.abs(joint_side).max()) + 4.0 * noise
    if peak > bound + 1e-6:
        raise AouError(diag(
            R406, f"the hand's peak acceleration {peak:.4g} m/s^2 at t={c.rest.t[at]:.3f}s "
            f"is more than the joints' motion there produces ({bound:.4g} m/s^2); this is "
            "an error of the measurement, not a value", Span.whole_file(c.path),
            measured=peak, bound=bound))


def _five(at: int, half: int, n: int) -> list[int]:
    """The distinct samples, in order, of five spread evenly over ``at - half`` ..
    ``at + half``, rounded half to even and kept ``half`` from either end of ``n``: as
    ``np.unique(np.clip(np.linspace(at - half, at + half, 5).round().astype(int), half,
    n - 1 - half))`` gives them. The five are ``at - half + k * half / 2``: whole or half
    numbers, exact in binary, which ``round`` rounds half to even as NumPy does."""
    return sorted({min(max(round(at - half + k * (half / 2)), half), n - 1 - half)
                   for k in range(5)})
