"""Time laws of a path coordinate ``s(t)``, rest to rest: TOPP-RA's law with a piecewise
constant ``s''`` (:class:`TimeLaw`), and its jerk-limited version (:class:`SmoothLaw`).

A :class:`SmoothLaw` is the moving average of a :class:`TimeLaw` over a window of
``T`` seconds::

    s_T(t) = (1/T) * integral of s over [t - T, t]

(``s`` is 0 before the motion and ``L`` after it). Differentiating under the integral,
every derivative of ``s_T`` is the difference quotient of the one below it:
``s_T' = (s(t) - s(t-T)) / T``, ``s_T'' = (s'(t) - s'(t-T)) / T`` and
``s_T''' = (s''(t) - s''(t-T)) / T``. So:

- the path jerk is finite, ``|s_T'''| <= (max s'' - min s'') / T``, and the acceleration
  is continuous, zero at both ends (the law starts and ends at rest, as a motion
  generator requires);
- ``|s_T''|`` is an average of ``|s''|``: it never exceeds the base law's peak, and equals
  it wherever the base law holds its peak for at least ``T`` (an accelerating phase of a
  declared ``a=`` lasts ``v / a``, tenths of a second; ``T`` is milliseconds);
- the same holds for the path speed, and the duration grows by exactly ``T``.

This is how a double-S (jerk-limited) profile is made from a trapezoid by a moving-average
filter; applied to TOPP-RA's law, it keeps what TOPP-RA knows of the joint limits.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

__all__ = ["SmoothLaw", "TimeLaw"]


@dataclass(frozen=True)
class TimeLaw:
    """``s(t)`` with constant ``s''`` between grid points (TOPP-RA's own output form).

    Attributes:
        s: grid of the path coordinate, shape (K,), increasing.
        sd: path speed at the grid points, shape (K,); zero at both ends.
        t: time at the grid points [s], shape (K,).
        u: path acceleration on each interval, shape (K - 1,).
    """

    s: np.ndarray
    sd: np.ndarray
    t: np.ndarray
    u: np.ndarray

    @classmethod
    def from_speeds(cls, s: np.ndarray, sd: np.ndarray) -> TimeLaw:
        ds = np.diff(s)
        mean = sd[:-1] + sd[1:]
        if np.any(mean <= 0):
            raise ValueError("path speed is zero on an interval")
        dt = 2.0 * ds / mean
        u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2.0 * ds)
        return cls(s, sd, np.concatenate([[0.0], np.cumsum(dt)]), u)

    @classmethod
    def bang_bang(cls, length: float, duration: float) -> TimeLaw:
        """Rest to rest over ``length`` in exactly ``duration``: accelerate, decelerate."""
        peak = 2.0 * length / duration
        return cls.from_speeds(np.array([0.0, length / 2, length]), np.array([0.0, peak, 0.0]))

    @property
    def duration(self) -> float:
        return float(self.t[-1])

    @property
    def length(self) -> float:
        return float(self.s[-1])

    def __call__(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``s, s', s''`` at local times ``tau`` (clipped to [0, duration])."""
        tau = np.clip(tau, 0.0, self.duration)
        i = np.clip(np.searchsorted(self.t, tau, side="right") - 1, 0, len(self.u) - 1)
        dt = tau - self.t[i]
        u = self.u[i]
        sd = self.sd[i] + u * dt
        s = self.s[i] + self.sd[i] * dt + 0.5 * u * dt * dt
        return s, sd, u

    @functools.cached_property
    def _area(self) -> np.ndarray:
        """``integral of s over [0, t_k]`` at the grid times, shape (K,)."""
        dt = np.diff(self.t)
        piece = self.s[:-1] * dt + self.sd[:-1] * dt**2 / 2 + self.u * dt**3 / 6
        return np.concatenate([[0.0], np.cumsum(piece)])

    def position(self, tau: np.ndarray) -> np.ndarray:
        """``s`` alone at local times ``tau``: :meth:`__call__`'s first."""
        return self(tau)[0]

    def area(self, tau: np.ndarray) -> np.ndarray:
        """``integral of s over [0, tau]`` alone: :meth:`state`'s last, computed the same
        way to the bit (a controller's view of the motion reads positions only)."""
        tau = np.asarray(tau, dtype=float)
        end = self.duration
        tc = np.clip(tau, 0.0, end)
        i = np.clip(np.searchsorted(self.t, tc, side="right") - 1, 0, len(self.u) - 1)
        dt = tc - self.t[i]
        area = self._area[i] + self.s[i] * dt + self.sd[i] * dt**2 / 2 + self.u[i] * dt**3 / 6
        return np.where(tau < 0.0, 0.0, area + np.where(tau > end, self.length * (tau - end),
                                                        0.0))

    def state(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``s, s', s''`` and ``integral of s over [0, tau]`` at any times: at rest at 0
        before the law, at rest at ``length`` after it. Each shape (len(tau),)."""
        tau = np.asarray(tau, dtype=float)
        end = self.duration
        tc = np.clip(tau, 0.0, end)
        i = np.clip(np.searchsorted(self.t, tc, side="right") - 1, 0, len(self.u) - 1)
        dt = tc - self.t[i]
        u, s0, sd0 = self.u[i], self.s[i], self.sd[i]
        sd = sd0 + u * dt
        s = s0 + sd0 * dt + 0.5 * u * dt * dt
        area = self._area[i] + s0 * dt + sd0 * dt**2 / 2 + u * dt**3 / 6
        before, after = tau < 0.0, tau > end
        rest = before | after
        s = np.where(after, self.length, s)
        sd = np.where(rest, 0.0, sd)
        u = np.where(rest, 0.0, u)
        area = np.where(before, 0.0, area + np.where(after, self.length * (tau - end), 0.0))
        return s, sd, u, area


@dataclass(frozen=True)
class SmoothLaw:
    """The jerk-limited law: ``base`` averaged over a moving window of ``window`` [s]
    (see the module's docstring). Lasts ``base.duration + window``."""

    base: TimeLaw
    window: float

    @property
    def duration(self) -> float:
        return self.base.duration + self.window

    @property
    def u(self) -> np.ndarray:
        """The base law's path accelerations; the smoothed law peaks at their largest
        magnitude wherever the base law holds it for ``window`` or longer."""
        return self.base.u

    def __call__(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``s, s', s''`` at local times ``tau`` (clipped to [0, duration])."""
        s, sd, sdd, _ = self.derivatives(tau)
        return s, sd, sdd

    def derivatives(self, tau: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``s, s', s'', s'''`` at local times ``tau`` (clipped to [0, duration]);
        ``s'''`` is piecewise constant between :meth:`breakpoints`."""
        tau = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration)
        w = self.window
        n = len(tau) if tau.ndim else 1
        # The base law at both ends of the window, in one pass.
        both = self.base.state(np.concatenate([tau.reshape(-1), tau.reshape(-1) - w]))
        (s1, sd1, u1, a1), (s0, sd0, u0, a0) = ([x[:n].reshape(tau.shape) for x in both],
                                                [x[n:].reshape(tau.shape) for x in both])
        s = np.where(tau >= self.duration, self.base.length, (a1 - a0) / w)
        return s, (s1 - s0) / w, (sd1 - sd0) / w, (u1 - u0) / w

    def position(self, tau: np.ndarray) -> np.ndarray:
        """``s`` alone at local times ``tau``: :meth:`derivatives`'s first, computed the
        same way to the bit from the base law's areas alone."""
        tau = np.clip(np.asarray(tau, dtype=float), 0.0, self.duration)
        w = self.window
        n = len(tau) if tau.ndim else 1
        both = self.base.area(np.concatenate([tau.reshape(-1), tau.reshape(-1) - w]))
        a1, a0 = both[:n].reshape(tau.shape), both[n:].reshape(tau.shape)
        return np.where(tau >= self.duration, self.base.length, (a1 - a0) / w)

    def jerk(self, tau: np.ndarray) -> np.ndarray:
        """``s'''`` at local times ``tau``."""
        return self.derivatives(tau)[3]

    def breakpoints(self) -> np.ndarray:
        """The times where ``s'''`` changes (``s''`` is linear between them), sorted."""
        return np.unique(np.concatenate([self.base.t, self.base.t + self.window]))

    def peak_acceleration(self) -> float:
        """The exact peak of ``|s''|`` (a piecewise linear function: its extremes are at
        the breakpoints); computed once per law (timing reads it twice), and kept on
        the way when :meth:`probed` has computed the breakpoints' values already."""
        return self._peak

    @functools.cached_property
    def _peak(self) -> float:
        return float(np.max(np.abs(self(self.breakpoints())[2])))

    def probe_times(self) -> np.ndarray:
        """Times that see every piece of the law: each breakpoint, just before and just
        after it, and the middle of each piece; sorted."""
        return np.sort(self._probe_times()[0])

    def _probe_times(self) -> tuple[np.ndarray, int]:
        """:meth:`probe_times` unsorted, the breakpoints first; and how many those are."""
        b = self.breakpoints()
        eps = 1e-9
        mid = (b[:-1] + b[1:]) / 2
        return (np.clip(np.concatenate([b, b + eps, mid, b - eps]), 0.0, self.duration),
                len(b))

    def probed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`derivatives` at the probe times (unsorted, the breakpoints first), for
        the jerk check; the peak acceleration is kept on the way, from the breakpoints'
        values: :meth:`derivatives` computes each time on its own, so these are the
        values it gives at the breakpoints alone, and the peak is the same to the bit."""
        tau, nb = self._probe_times()
        out = self.derivatives(tau)
        self.__dict__.setdefault("_peak", float(np.max(np.abs(out[2][:nb]))))
        return out
