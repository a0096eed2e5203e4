"""Whether a noisy recording's episodes of one kind differ by more than its noise.

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

import numpy as np

from ..core.codes import R403
from ..lang.descriptors import EpisodeValues, qualify, spread
from .recognisers import every_named, extra_descriptors

__all__ = ["beyond_noise", "per_episode", "unequal"]


def per_episode(episodes: list[EpisodeValues]) -> dict[str, list[float]]:
    """Per non-count descriptor, the eleven's and the plugins', the values of the
    episodes it aggregates."""
    out = spread(episodes)
    eps = qualify(episodes)
    for d in extra_descriptors():
        vals = [float(e.values[d.key]) for e in eps
                if e.kind == d.kind and e.counts and d.key in e.values]
        if vals and not d.is_count:
            out[d.name] = vals
    return out


def unequal(table: Mapping, name: str, vals: list[float], margin: float = 0.0) -> bool:
    """Whether the episodes' values differ by more than the descriptor's tolerance, and
    by ``margin`` more."""
    return max(vals) - min(vals) - margin > table[name].tolerance(float(np.median(vals)))


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
