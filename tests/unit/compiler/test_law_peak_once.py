"""A smoothed time law's peak acceleration is read twice by timing (the Cartesian check,
then the shortfall): it is computed once per law, and is the exact peak over the law's
breakpoints (where a piecewise linear s'' has its extremes)."""

from __future__ import annotations

import numpy as np

from aou_dsl.compiler.timelaw import SmoothLaw, TimeLaw


def test_the_peak_is_computed_once_per_law_and_is_the_breakpoints_peak(monkeypatch):
    law = SmoothLaw(TimeLaw.bang_bang(0.4, 1.6), 0.05)
    calls: list[int] = []
    real = SmoothLaw.derivatives
    monkeypatch.setattr(SmoothLaw, "derivatives",
                        lambda self, tau: calls.append(len(tau)) or real(self, tau))
    first = law.peak_acceleration()
    assert law.peak_acceleration() == first and len(calls) == 1
    dense = np.linspace(0.0, law.duration, 20001)
    assert first == np.max(np.abs(real(law, law.breakpoints())[2]))
    assert first >= np.max(np.abs(real(law, dense)[2])) * (1.0 - 1e-12)  # rounding
    other = SmoothLaw(TimeLaw.bang_bang(0.4, 1.2), 0.05)  # another law: its own peak
    assert other.peak_acceleration() > first and len(calls) == 2
