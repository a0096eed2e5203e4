"""A timed joint path, ``q(t) = path(s(t))``: a spline through the IK's waypoints and the
time law that runs along it. The unit that timing makes and the peak checks read."""

from __future__ import annotations

import numpy as np

from .timelaw import SmoothLaw, TimeLaw

__all__ = ["PathSegment"]


class PathSegment:
    """A timed joint path: ``q(t) = path(s(t))``, shape (n,) per sample.

    ``spline`` may have more columns than joints (TOPP-RA's path carries the virtual
    coordinate last); only the first ``n``, the joints, are kept. ``law`` is a
    :class:`~.timelaw.TimeLaw` or a :class:`~.timelaw.SmoothLaw`.
    """

    def __init__(self, s_way: np.ndarray, q_way: np.ndarray, law: TimeLaw | SmoothLaw,
                 spline=None):
        from scipy.interpolate import CubicSpline, PPoly

        self.n = n = q_way.shape[1]
        if spline is None:
            spline = CubicSpline(s_way, q_way, axis=0)
        elif spline.c.shape[-1] != n:  # the joints' columns only (each is its own cubic)
            spline = PPoly.construct_fast(np.ascontiguousarray(spline.c[..., :n]), spline.x,
                                          spline.extrapolate)
        self.spline = spline
        self.d1 = self.spline.derivative(1)
        self.d2 = self.spline.derivative(2)
        self.d3 = self.spline.derivative(3)
        self.law = law

    def with_law(self, law: TimeLaw | SmoothLaw) -> PathSegment:
        """The same path under another time law."""
        seg = object.__new__(PathSegment)
        seg.__dict__.update(self.__dict__)
        seg.law = law
        return seg

    @property
    def duration(self) -> float:
        return self.law.duration

    def sample(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Joint positions, velocities, accelerations at local times; each (len(tau), n)."""
        s, sd, sdd = self.law(tau)
        qs, qss = self.d1(s), self.d2(s)
        return (self.spline(s), qs * sd[:, None],
                qss * (sd * sd)[:, None] + qs * sdd[:, None])

    def positions(self, tau: np.ndarray) -> np.ndarray:
        """Joint positions at local times, (len(tau), n): :meth:`sample`'s first."""
        return self.spline(self.law.position(tau))

    def jerk(self, tau: np.ndarray) -> np.ndarray:
        """Joint jerks at local times, shape (len(tau), n):
        ``q_sss s'^3 + 3 q_ss s' s'' + q_s s'''`` (a plain law's ``s'''`` counts as 0)."""
        if isinstance(self.law, SmoothLaw):
            return self.path_jerk(*self.law.derivatives(tau))
        s, sd, sdd = self.law(tau)
        return self.path_jerk(s, sd, sdd, np.zeros_like(s))

    def path_jerk(self, s: np.ndarray, sd: np.ndarray, sdd: np.ndarray, sddd: np.ndarray
                  ) -> np.ndarray:
        """Joint jerks, (len(s), n), where the law is at ``s`` with these derivatives."""
        return (self.d3(s) * (sd**3)[:, None] + 3.0 * self.d2(s) * (sd * sdd)[:, None]
                + self.d1(s) * sddd[:, None])
