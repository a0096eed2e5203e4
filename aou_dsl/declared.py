"""The descriptors a behaviour declares, named as in MODEL.md s5 (pure Python).

Descriptor form: the file's values, in the units of MODEL.md (m, s, m/s^2, deg, deg/s).
Sequence form: the same definitions applied to the sequence as laid out (adjacent pauses
are one pause; a retreat counts only between two pauses; a gaze only when it ends at a
pause), so that what is declared is what ``aouc measure`` can find.
"""

from __future__ import annotations

import math

from .ir import Behaviour

__all__ = [
    "DESCRIPTORS",
    "compare_descriptors",
    "declared_descriptors",
    "timeline_descriptors",
    "tolerance",
]

DESCRIPTORS = (
    "approach_acceleration",
    "pause_count",
    "pause_duration",
    "retreat_count",
    "retreat_distance",
    "retreat_acceleration",
    "horizontal_gaze",
    "vertical_gaze",
    "tilt_angle",
    "tilt_velocity",
    "shiver_amplitude",
)


def _descriptor_form(b: Behaviour) -> dict[str, float | int | None]:
    d: dict[str, float | int | None] = dict.fromkeys(DESCRIPTORS)
    d["pause_count"] = 0
    d["retreat_count"] = 0
    for p in b.primitives:
        if p.count == 0:
            continue
        if p.kind == "approach":
            d["approach_acceleration"] = p.a
        elif p.kind == "pause":
            d["pause_count"], d["pause_duration"] = p.count, p.duration
        elif p.kind == "retreat":
            d["retreat_count"] = p.count
            d["retreat_distance"], d["retreat_acceleration"] = p.length, p.a
        elif p.kind == "gaze":
            d[f"{p.plane}_gaze"] = math.degrees(p.angle)
        elif p.kind == "tilt":
            d["tilt_angle"], d["tilt_velocity"] = math.degrees(p.angle), math.degrees(p.v)
        elif p.kind == "shiver":
            d["shiver_amplitude"] = math.degrees(p.amplitude)
    return d


def timeline_descriptors(eps) -> dict[str, float | int | None]:
    """MODEL.md's definitions applied to a laid-out timeline (a sequence of episodes):
    what a trajectory following it shows."""
    d: dict[str, float | int | None] = dict.fromkeys(DESCRIPTORS)
    # Pauses with nothing moving between them are one pause.
    merged: list = []
    for e in eps:
        if e.kind == "pause" and merged and merged[-1][0] == "pause":
            merged[-1] = ("pause", merged[-1][1] + e.duration)
        else:
            merged.append((e.kind, e.duration))
    pauses = [dur for kind, dur in merged if kind == "pause"]
    d["pause_count"] = len(pauses)
    if pauses:
        d["pause_duration"] = max(pauses)
    approaches = [e for e in eps if e.kind == "approach"]
    if approaches:
        d["approach_acceleration"] = max(e.a for e in approaches)
    retreats = [e for i, e in enumerate(eps) if e.kind == "retreat" and 0 < i < len(eps) - 1
                and eps[i - 1].kind == "pause" and eps[i + 1].kind == "pause"]
    d["retreat_count"] = len(retreats)
    if retreats:
        d["retreat_distance"] = max(e.path_length for e in retreats)
        d["retreat_acceleration"] = max(e.a for e in retreats)
    for plane, attr in (("horizontal", "h"), ("vertical", "v")):
        gz = [e for i, e in enumerate(eps) if e.kind == "gaze" and e.plane == plane
              and i + 1 < len(eps) and eps[i + 1].kind == "pause"]
        if gz:
            d[f"{plane}_gaze"] = max(abs(math.degrees(getattr(e.end, attr))) for e in gz)
    tilts = [e for e in eps if e.kind == "tilt"]
    if tilts:
        d["tilt_angle"] = max(math.degrees(e.path_length) for e in tilts)
        d["tilt_velocity"] = max(math.degrees(e.path_length) / e.duration for e in tilts)
    shivers = [e for e in eps if e.kind == "shiver"]
    if shivers:
        d["shiver_amplitude"] = max(math.degrees(e.amplitude) for e in shivers)
    return d


def declared_descriptors(b: Behaviour) -> dict[str, float | int | None]:
    """The eleven descriptors the behaviour declares; None where a primitive is absent."""
    if b.form == "descriptor":
        return _descriptor_form(b)
    from .compiler.layout import layout

    return timeline_descriptors(layout(b).episodes)


#: How close a measured descriptor must be to the declared one (issue tolerances):
#: counts exactly; durations 2 % or 20 ms; distances 1 mm; angles 0.5 deg;
#: accelerations 3 %; angular velocities 2 % or 0.5 deg/s.
def tolerance(name: str, declared: float) -> float:
    if name.endswith("_count"):
        return 0.0
    if name == "pause_duration":
        return max(0.02, 0.02 * declared)
    if name == "retreat_distance":
        return 1e-3
    if name.endswith("acceleration"):
        return 0.03 * declared
    if name == "tilt_velocity":
        return max(0.5, 0.02 * declared)
    return 0.5  # angles [deg]


def compare_descriptors(declared: dict, measured: dict
                        ) -> list[tuple[str, float | int | None, float | int | None]]:
    """The descriptors whose measured value misses the declared one: (name, declared,
    measured). A descriptor declared absent must be measured absent, and vice versa."""
    out = []
    for name in DESCRIPTORS:
        want, got = declared.get(name), measured.get(name)
        if want is None or got is None:
            if (want is None) != (got is None) and not (name.endswith("_count")):
                out.append((name, want, got))
            continue
        if abs(got - want) > tolerance(name, want) + 1e-12:
            out.append((name, want, got))
    return out
