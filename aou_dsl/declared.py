"""The descriptors a behaviour declares, named as in MODEL.md s5 (pure Python).

Descriptor form: the file's values, in the units of MODEL.md (m, s, m/s^2, deg, deg/s).
Sequence form: the same definitions applied to the sequence as laid out (adjacent pauses
are one pause; a retreat counts only between two pauses; a gaze only when it ends at a
pause), so that what is declared is what ``aouc measure`` can find.
"""

from __future__ import annotations

import math

from .ir import Behaviour

__all__ = ["DESCRIPTORS", "declared_descriptors"]

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


def _sequence_form(b: Behaviour) -> dict[str, float | int | None]:
    from .compiler.layout import layout

    eps = layout(b).episodes
    d: dict[str, float | int | None] = dict.fromkeys(DESCRIPTORS)
    pauses = [e for e in eps if e.kind == "pause"]
    d["pause_count"] = len(pauses)
    if pauses:
        d["pause_duration"] = max(e.duration for e in pauses)
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
    return _descriptor_form(b) if b.form == "descriptor" else _sequence_form(b)
