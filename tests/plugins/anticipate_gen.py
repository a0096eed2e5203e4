"""Random behaviours that use the plugin's ``anticipate``, with the descriptors they
declare worked out from the definitions, not from aou's layout or measurement.

Each file is a sequence: from the start, ``k`` times an anticipation directly followed by
an approach piece (the last to the standoff), each approach followed by a pause, and
between two of them, sometimes, a retreat with a pause after it. So, by the definitions:

- every anticipation is directly before an approach: ``anticipate_count`` is ``k`` and
  ``anticipate_distance`` the median of their distances;
- a retreat counts when a pause is directly before and after it, which each of these
  has: ``retreat_count`` is their number, ``retreat_distance`` their median distance,
  ``retreat_acceleration`` their largest peak acceleration;
- no two pauses touch: ``pause_count`` is the number of pause statements,
  ``pause_duration`` the median of their durations;
- ``approach_acceleration`` is the largest approach's peak acceleration (an
  anticipation moves away from the goal: it is no approach).
"""

from __future__ import annotations

import random
import statistics
from dataclasses import dataclass, field

__all__ = ["Generated", "generate"]


@dataclass
class Generated:
    """A file's text and the descriptors it declares (by name; absent ones left out)."""

    text: str
    expected: dict[str, float | int | None] = field(default_factory=dict)


def _mm(rng: random.Random, lo: int, hi: int) -> float:
    return rng.randint(lo, hi) / 1000.0


def generate(seed: int) -> Generated:
    rng = random.Random(seed)
    start = _mm(rng, 300, 380)
    standoff = _mm(rng, 90, 120)
    k = rng.randint(1, 3)
    lines = ["sequence {"]
    pose = start
    anticipations: list[float] = []
    retreats: list[tuple[float, float]] = []
    approach_a: list[float] = []
    pauses: list[float] = []
    for i in range(k):
        d = _mm(rng, 8, 45)
        a = rng.choice((0.08, 0.12, 0.2, 0.3))
        lines.append(f"  anticipate {d * 1000:g}mm a={a:g}")
        anticipations.append(d)
        pose += d
        aa = rng.choice((0.05, 0.08, 0.1, 0.15))
        approach_a.append(aa)
        if i == k - 1:
            lines.append(f"  approach a={aa:g}")
            pose = standoff
        else:  # an equal share of what is left of the way to the standoff
            target = standoff + (pose - d - standoff) * (k - 1 - i) / (k - i)
            length = round(pose - target, 3)
            lines.append(f"  approach {length * 1000:g}mm a={aa:g}")
            pose -= length
        p = rng.choice((0.5, 0.8, 1.0, 1.5))
        lines.append(f"  pause {p:g}s")
        pauses.append(p)
        if i < k - 1 and rng.random() < 0.5:
            r, ra = _mm(rng, 10, 40), rng.choice((0.1, 0.2))
            lines.append(f"  retreat {r * 1000:g}mm a={ra:g}")
            p = rng.choice((0.5, 1.0))
            lines.append(f"  pause {p:g}s")
            retreats.append((r, ra))
            pauses.append(p)
            pose += r
    lines.append("}")
    head = [f"behaviour gen{seed}", "robot panda", f"start {start * 1000:g}mm",
            f"standoff {standoff * 1000:g}mm"]
    expected: dict[str, float | int | None] = {
        "anticipate_count": k,
        "anticipate_distance": statistics.median(anticipations),
        "approach_acceleration": max(approach_a),
        "pause_count": len(pauses),
        "pause_duration": statistics.median(pauses),
        "retreat_count": len(retreats),
        "retreat_distance": statistics.median(r for r, _ in retreats) if retreats else None,
        "retreat_acceleration": max(ra for _, ra in retreats) if retreats else None,
    }
    return Generated("\n".join([*head, *lines]) + "\n", expected)
