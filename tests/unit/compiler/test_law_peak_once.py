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



def _laws():
    base = TimeLaw.from_speeds(np.array([0.0, 0.01, 0.05, 0.12, 0.2, 0.23]),
                               np.array([0.0, 0.09, 0.2, 0.2, 0.11, 0.0]))
    return [SmoothLaw(TimeLaw.bang_bang(0.4, 1.6), 0.05), SmoothLaw(base, 0.013),
            SmoothLaw(base, 0.4)]


def test_the_probed_values_are_each_probe_times_own_and_keep_the_same_peak(monkeypatch):
    """The jerk check reads the law at its probe times once, the breakpoints first: the
    values are those of the sorted probe times, one by one, and the peak kept on the way
    (no second reading) is the one the breakpoints alone give, to the bit."""
    for law in _laws():
        b = law.breakpoints()
        unsorted = np.clip(np.concatenate([b, b + 1e-9, (b[:-1] + b[1:]) / 2, b - 1e-9]),
                           0.0, law.duration)
        order = np.argsort(unsorted, kind="stable")
        want = law.derivatives(law.probe_times())
        probed = law.probed()
        for got, w in zip(probed, want, strict=True):
            assert np.array_equal(got[order], w)
        calls: list[int] = []
        real = SmoothLaw.derivatives
        monkeypatch.setattr(SmoothLaw, "derivatives", lambda self, tau, calls=calls,
                            real=real: calls.append(len(tau)) or real(self, tau))
        peak = law.peak_acceleration()
        assert calls == []
        assert peak == np.max(np.abs(real(law, b)[2]))
        assert SmoothLaw(law.base, law.window).peak_acceleration() == peak
        monkeypatch.undo()
