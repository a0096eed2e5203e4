"""The Savitzky-Golay filter, written for the measurement: the value or a derivative, at
each sample, of the polynomial fitted by least squares to the window around it.

The measurement derives its thresholds from these numbers, so they must not move by a
bit from one release to the next. The filter therefore does its arithmetic in one fixed
order, the order of the library routine the measurement was first calibrated with (the
weights from a least-squares solve; a symmetric or antisymmetric set of weights applied
to mirrored pairs of samples, outermost pair first; the ends fitted with their own
polynomial). It needs only NumPy: importing SciPy's signal package costs a cold command
about a second (tests/unit/measuring/test_savgol.py holds the two to the same bits).
:func:`savgol_rows` gives some rows of it, the same bits. :func:`savgol_1d` sums each
window in NumPy's own order instead, equal to rounding: the measurement uses it only on a
recording's 1-D travels, whose noise is far above the rounding, never on a computed
trajectory.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.memo import cached

__all__ = ["savgol", "savgol_1d", "savgol_rows", "savgol_weights"]

#: How far two mirrored weights may differ and still count as equal (or opposite), so
#: that the pair is summed before it is weighted.
_MIRROR_TOLERANCE = float(np.finfo(float).eps)
#: Values filtered at a time (rows times columns): a few hundred kilobytes.
_BLOCK = 1 << 15
_EPS = float(np.finfo(np.float64).eps)


@cached(maxsize=256)
def savgol_weights(window: int, order: int, deriv: int, delta: float,
                   reverse: bool = False) -> np.ndarray:
    """Weights ``c`` such that ``c @ x[i - m:i + m + 1]`` is the ``deriv``-th derivative at
    the centre of the polynomial of degree ``order`` fitted by least squares to the
    ``window`` samples ``x`` (``m = window // 2``), ``delta`` apart. With ``reverse`` the
    weights are solved for the samples in reverse order, then put back in order (the
    same numbers up to rounding; the filter uses these). Read-only: they are cached.

    The derivative at the centre is ``deriv!`` times the polynomial's coefficient of
    ``x**deriv``, so the weights are the minimum-norm solution of ``A c = e`` where row
    ``k`` of ``A`` holds the offsets to the power ``k``."""
    half, rem = divmod(window, 2)
    centre = half if rem else half - 0.5
    if deriv > order:
        return _frozen(np.zeros(window))
    offsets = np.arange(-centre, window - centre, dtype=np.float64)
    if reverse:
        offsets = offsets[::-1]
    design = offsets ** np.arange(order + 1, dtype=np.float64).reshape(-1, 1)
    target = np.zeros(order + 1)
    target[deriv] = float(math.factorial(deriv)) / (delta ** deriv)
    rcond = _EPS * max(design.shape)
    weights = np.linalg.lstsq(design, target, rcond=rcond)[0]
    return _frozen(weights[::-1].copy() if reverse else weights)


def _frozen(a: np.ndarray) -> np.ndarray:
    """``a`` made read-only (a cached array is shared by every caller)."""
    a.flags.writeable = False
    return a


def savgol(x: np.ndarray, window: int, order: int, deriv: int = 0,
           delta: float = 1.0) -> np.ndarray:
    """The filter along axis 0 of ``x`` (float64, 1-D or more), ``window`` odd and at
    most ``len(x)``, ``order`` under ``window``. A sample within ``window // 2`` of an
    end takes the polynomial fitted to the first (or last) ``window`` samples."""
    x = np.asarray(x, dtype=np.float64)
    weights, mirror = _applied_weights(window, order, deriv, delta)
    out = np.empty_like(x)
    half = window // 2
    n = len(x)
    # A block of rows at a time, so that each pass over the samples (one per pair of
    # weights) stays in the processor's cache: the same operations on each sample.
    rows = max(1, _BLOCK // max(1, x[:1].size))
    for s in range(half, n - half, rows):
        e = min(n - half, s + rows)
        _correlate(x[s - half:e + half], weights, mirror, out[s:e])
    _fit_end(x, out, slice(0, window), slice(0, half), order, deriv, delta)
    _fit_end(x, out, slice(n - window, n), slice(n - half, n), order, deriv, delta)
    return out


def savgol_1d(x: np.ndarray, window: int, order: int, deriv: int = 0,
              delta: float = 1.0) -> np.ndarray:
    """:func:`savgol` of a 1-D ``x``, each window's sum a dot product of NumPy's
    correlation (in its own order of summation): equal to it to rounding (about 1e-15 of
    the signal's scale), and on a motion's few thousand samples several times faster,
    where the fixed order's pass per weight costs more in calls than in arithmetic. The
    ends are fitted as :func:`savgol` fits them."""
    x = np.asarray(x, dtype=np.float64)
    n, half = len(x), window // 2
    if x.ndim != 1 or window % 2 == 0 or n < window or half < 1:
        return savgol(x, window, order, deriv, delta)
    weights, _ = _applied_weights(window, order, deriv, delta)
    out = np.empty_like(x)
    out[half:n - half] = np.correlate(x, weights, "valid")
    _fit_end(x, out, slice(0, window), slice(0, half), order, deriv, delta)
    _fit_end(x, out, slice(n - window, n), slice(n - half, n), order, deriv, delta)
    return out


def savgol_rows(x: np.ndarray, window: int, order: int, deriv: int, delta: float,
                start: int, stop: int) -> np.ndarray:
    """``savgol(x, window, order, deriv, delta)[start:stop]``, the same numbers, from
    only those rows' windows (each value is its own window's sum, in the same order)."""
    x = np.asarray(x, dtype=np.float64)
    n, half = len(x), window // 2
    start, stop = max(0, start), min(n, stop)
    out = np.empty((max(0, stop - start),) + x.shape[1:])
    if stop <= start:
        return out
    weights, mirror = _applied_weights(window, order, deriv, delta)
    rows = max(1, _BLOCK // max(1, x[:1].size))
    lo, hi = max(start, half), min(stop, n - half)
    for s in range(lo, hi, rows):
        e = min(hi, s + rows)
        # Their samples copied row by row (a recording's joints are laid out by column:
        # a few rows of them are far apart), the same values in the same order.
        _correlate(np.ascontiguousarray(x[s - half:e + half]), weights, mirror,
                   out[s - start:e - start])
    _fit_end(x, out, slice(0, window), slice(start, min(stop, half)), order, deriv, delta,
             start)
    _fit_end(x, out, slice(n - window, n), slice(max(start, n - half), stop), order,
             deriv, delta, start)
    return out


@cached(maxsize=256)
def _applied_weights(window: int, order: int, deriv: int, delta: float
                     ) -> tuple[np.ndarray, int]:
    """The weights the filter applies (:func:`savgol_weights` solved in reverse), and
    whether they are mirrored (:func:`_mirror`)."""
    weights = savgol_weights(window, order, deriv, delta, reverse=True)
    return weights, _mirror(weights)


def _mirror(weights: np.ndarray) -> int:
    """1 when the weights are symmetric about their centre, -1 when antisymmetric, else
    0 (each within :data:`_MIRROR_TOLERANCE`; an even count is neither)."""
    half = len(weights) // 2
    if len(weights) % 2 == 0:
        return 0
    left, right = weights[:half][::-1], weights[half + 1:]
    if np.all(np.abs(right - left) <= _MIRROR_TOLERANCE):
        return 1
    if np.all(np.abs(right + left) <= _MIRROR_TOLERANCE):
        return -1
    return 0


def _correlate(x: np.ndarray, weights: np.ndarray, mirror: int, out: np.ndarray) -> None:
    """``out[i - m] = sum_k weights[k] * x[i - m + k]`` for every ``i`` with ``m`` samples
    on either side, one weight at a time across all samples. Mirrored weights multiply
    the sum (or difference) of their two samples, outermost pair first, after the centre
    term."""
    w = len(weights)
    half = w // 2
    n = len(out)
    term = np.empty_like(out)

    def shifted(k: int) -> np.ndarray:
        return x[k:k + n]

    if mirror:
        np.multiply(shifted(half), weights[half], out=out)
        combine = np.add if mirror > 0 else np.subtract
        for k in range(half):
            combine(shifted(k), shifted(w - 1 - k), out=term)
            term *= weights[k]
            out += term
        return
    np.multiply(shifted(w - 1), weights[w - 1], out=out)
    for k in range(w - 1):
        np.multiply(shifted(k), weights[k], out=term)
        out += term


def _fit_end(x: np.ndarray, out: np.ndarray, window: slice, place: slice, order: int,
             deriv: int, delta: float, offset: int = 0) -> None:
    """``out[place]`` (shifted back by ``offset`` rows): the ``deriv``-th derivative of
    the polynomial of degree ``order`` fitted by least squares to ``x[window]`` (each
    column on its own)."""
    if place.stop <= place.start:
        return
    seg = x[window].reshape(window.stop - window.start, -1)
    coeffs = _polyfit(seg, order)
    coeffs = _derivative(coeffs, deriv)
    at = _places(place.start - window.start, place.stop - window.start)
    values = np.zeros(at.shape)
    for row in coeffs:  # Horner's scheme, highest power first
        values = values * at + row
    out[place.start - offset:place.stop - offset] = (values / (delta ** deriv)).reshape(
        (len(at),) + x.shape[1:])


def _polyfit(y: np.ndarray, order: int) -> np.ndarray:
    """Coefficients (highest power first, one column per column of ``y``) of the
    least-squares polynomial through ``(k, y[k])``, ``k = 0, 1, 2, ...``."""
    lhs, scale = _edge_design(len(y), order)
    rcond = len(y) * _EPS
    coeffs = np.linalg.lstsq(lhs, y, rcond=rcond)[0]
    return (coeffs.T / scale).T


@cached(maxsize=64)
def _edge_design(window: int, order: int) -> tuple[np.ndarray, np.ndarray]:
    """The powers of ``0, 1, .. window - 1`` (highest first) as the end fits solve
    them, each scaled to unit norm (a better conditioned solve), and the scales.
    Read-only: they are cached."""
    t = np.arange(0, window, dtype=np.float64)
    lhs = t[:, None] ** np.arange(order, -1, -1, dtype=np.float64)[None, :]
    scale = np.sqrt(np.sum(lhs * lhs, axis=0))
    lhs /= scale
    return _frozen(lhs), _frozen(scale)


def _derivative(coeffs: np.ndarray, deriv: int) -> np.ndarray:
    """The ``deriv``-th derivative of polynomials given by their coefficients (highest
    power first, one polynomial per column): the top rows kept, each multiplied by its
    power once per differentiation."""
    n = len(coeffs)
    if deriv == 0:
        return coeffs
    if n <= deriv:
        return np.zeros_like(coeffs[:1])
    out = coeffs[:-deriv].copy()
    for powers in _powers(n, deriv):
        out *= powers.reshape((n - deriv,) + (1,) * (out.ndim - 1))
    return out


@cached(maxsize=64)
def _powers(n: int, deriv: int) -> tuple[np.ndarray, ...]:
    """The factors :func:`_derivative` multiplies the top ``n - deriv`` coefficients of
    a polynomial with ``n`` by, one array per differentiation (read-only: cached)."""
    return tuple(_frozen(np.arange(n - k - 1, deriv - k - 1, -1, dtype=np.float64))
                 for k in range(deriv))


@cached(maxsize=64)
def _places(start: int, stop: int) -> np.ndarray:
    """The offsets ``start .. stop - 1`` into an end's window where the filter takes
    that end's fit, as a column (read-only: cached)."""
    return _frozen(np.arange(start, stop, dtype=np.float64).reshape(-1, 1))
