"""What a noisy recording's episodes say of the trust its values deserve: whether
episodes of one kind differ by more than the noise (R403, below), and how much the noise
moves a peak acceleration's own reading (:func:`episode_noise`).

R403 says that the episodes of one kind differ by more than the descriptor's tolerance.
On a recording, each episode's value carries the noise too, so equal episodes can read
apart. Five equal pauses of hesitant, logged at 1e-3 rad, read between 1.63 and 1.68 s
against a tolerance of 0.033 s.

The re-noised copies that give the intervals (:mod:`.uncertainty`) read each episode
again. A copy that reads as many episodes of the kind as the recording pairs them with
the recording's by their order. The std of those readings across the copies is each
episode's own uncertainty. The note stays when the two farthest episodes differ by more
than the tolerance plus what the noise can put between them: Student's t for that many
copies times the two episodes' combined std. Otherwise the difference is the noise's,
and the value's interval already carries it. With fewer than two such copies nothing is
known of the noise, and the note stays.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from ..core.codes import R403
from ..lang.descriptors import REGISTRY, EpisodeValues, qualify, spread
from .recognisers import every_named, extra_descriptors
from .signal import median0

__all__ = ["beyond_noise", "episode_noise", "per_episode", "unequal"]

#: A two-sided 95 % interval of a normal reading, in its stds.
Z95 = 1.96


def per_episode(episodes: list[EpisodeValues]) -> dict[str, list[float]]:
    """Per non-count descriptor, the eleven's and the plugins', the values of the
    episodes it aggregates."""
    out = spread(episodes)
    extra = extra_descriptors()
    eps = qualify(episodes) if extra else []  # without plugins, nothing more to read
    for d in extra:
        vals = [float(e.values[d.key]) for e in eps
                if e.kind == d.kind and e.counts and d.key in e.values]
        if vals and not d.is_count:
            out[d.name] = vals
    return out


def unequal(table: Mapping, name: str, vals: list[float], margin: float = 0.0) -> bool:
    """Whether the episodes' values differ by more than the descriptor's tolerance, and
    by ``margin`` more."""
    return max(vals) - min(vals) - margin > table[name].tolerance(_median(vals))


def _median(vals: list[float]) -> float:
    """``float(np.median(vals))``: of finite values, the middle one or the mean of the
    middle two (as median0 takes it, NumPy's number); otherwise NumPy's own."""
    if all(math.isfinite(v) for v in vals):
        return float(median0(np.asarray(vals, float)))
    return float(np.median(vals))


def beyond_noise(m, copies: list, t95: Mapping[int, float]) -> None:
    """Drop from ``m``'s diagnostics each R403 whose spread the noise explains.

    ``copies``: the copies' measurements; ``t95``: Student's t for 95 % by degrees of
    freedom."""
    table = every_named()
    kept = []
    for d in m.diagnostics:
        if d.code == R403 and _within_noise(d.fields["descriptor"], d.fields["values"],
                                            copies, t95, table):
            continue
        kept.append(d)
    m.diagnostics[:] = kept


def _within_noise(name: str, values: list[float], copies: list,
                  t95: Mapping[int, float], table: Mapping) -> bool:
    vals = np.asarray(values, float)
    reads = [r for r in (per_episode(c.episodes).get(name) for c in copies)
             if r is not None and len(r) == len(vals)]
    if len(reads) < 2:
        return False
    sd = np.std(np.asarray(reads, float), axis=0, ddof=1)
    hi, lo = int(np.argmax(vals)), int(np.argmin(vals))
    noise = t95[min(len(reads) - 1, max(t95))] * math.hypot(sd[hi], sd[lo])
    return not unequal(table, name, values, noise)


def episode_noise(m, values: Mapping) -> None:
    """Widen the interval of each peak acceleration of ``m`` to hold what the noise
    gives the reading of the episode it comes from (that episode's
    ``peak_acceleration_sd``, the joints' noise carried through the acceleration's
    filter): its value +- 1.96 of those stds.

    The copies can miss that: they are made about the recording smoothed, which keeps a
    bump the noise made in a short piece of motion, so every copy reads it again. Hesitant
    logged with 1e-3 rad of noise at 250 Hz split its first approach at 0.65 s; the 1 cm
    piece read 1.01 m/s^2 (its own std 0.45), every copy read it within 0.0014, and the
    approach's 0.05 m/s^2 became a trusted 1.01. Widened, such a value is wider than a
    fifth of itself and is not to be trusted (R411), as it should not be."""
    eps = qualify(m.episodes)
    for name, d in every_named().items():
        v, s = values.get(name), m.uncertainty.get(name)
        if d.is_count or d.key != "peak_acceleration" or not isinstance(v, float) or \
                s is None or s.low is None or s.high is None:
            continue
        sds = [float(e.values["peak_acceleration_sd"]) for e in eps
               if e.kind == d.kind and e.counts and e.values.get(d.key) == v
               and "peak_acceleration_sd" in e.values]
        if not sds:
            continue
        half = Z95 * max(sds)
        low = min(s.low, v - half)
        m.uncertainty[name] = replace(s, low=max(low, 0.0) if name in REGISTRY else low,
                                      high=max(s.high, v + half))
