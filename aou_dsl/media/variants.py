"""``aouc variants``: the study's Part B stimuli, pairs that differ in one descriptor.

From a descriptor-form file and ``NAME=LOW,HIGH``, two files are made that are the
original text with one statement rewritten: the one that sets NAME. Comments, order and
every other statement stay byte for byte, so the pair differs in that descriptor only.
Values are in the descriptor's unit (MODEL.md s5: m, s, m/s^2, deg, deg/s; counts are
whole numbers). Both files must lint without errors, or neither is written.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..diagnostics import AouError, Span, diag
from ..ir import Behaviour, Primitive

__all__ = ["DESCRIPTOR_FIELDS", "Variant", "format_primitive", "make_variants"]

#: descriptor -> (primitive kind, gaze plane or None, field, to IR units)
DESCRIPTOR_FIELDS = {
    "approach_acceleration": ("approach", None, "a", 1.0),
    "pause_count": ("pause", None, "count", None),
    "pause_duration": ("pause", None, "duration", 1.0),
    "retreat_count": ("retreat", None, "count", None),
    "retreat_distance": ("retreat", None, "length", 1.0),
    "retreat_acceleration": ("retreat", None, "a", 1.0),
    "horizontal_gaze": ("gaze", "horizontal", "angle", math.pi / 180),
    "vertical_gaze": ("gaze", "vertical", "angle", math.pi / 180),
    "tilt_angle": ("tilt", None, "angle", math.pi / 180),
    "tilt_velocity": ("tilt", None, "v", math.pi / 180),
    "shiver_amplitude": ("shiver", None, "amplitude", math.pi / 180),
}


def _g(x: float) -> str:
    return f"{x:.6g}"


def format_primitive(p: Primitive) -> str:
    """A descriptor-form statement that validates back to ``p`` (keys written in full)."""
    rep = f" x{p.count}" if p.count != 1 else ""
    if p.kind == "approach":
        return f"approach a={_g(p.a)} v={_g(p.v)}"
    if p.kind == "pause":
        return f"pause {_g(p.duration)}s{rep}"
    if p.kind == "retreat":
        return f"retreat {_g(p.length)}m a={_g(p.a)} v={_g(p.v)}{rep}"
    if p.kind == "gaze":
        return (f"gaze {p.plane} {_g(math.degrees(p.angle))}deg "
                f"v={_g(math.degrees(p.v))}deg/s{rep}")
    if p.kind == "tilt":
        return f"tilt {_g(math.degrees(p.angle))}deg v={_g(math.degrees(p.v))}deg/s{rep}"
    return (f"shiver {_g(math.degrees(p.amplitude))}deg f={_g(p.f)}Hz "
            f"for {_g(p.duration)}s{rep}")


@dataclass(frozen=True)
class Variant:
    label: str  # "low" or "high"
    value: float
    text: str


def _replace(text: str, span: Span, new: str) -> str:
    lines = text.splitlines(keepends=True)
    line = lines[span.line - 1]
    lines[span.line - 1] = line[:span.col - 1] + new + line[span.end_col - 1:]
    return "".join(lines)


def make_variants(b: Behaviour, text: str, descriptor: str, low: float, high: float
                  ) -> list[Variant]:
    """The low and high variants of ``b`` (parsed from ``text``) in one descriptor.

    Raises:
        AouError: the descriptor is unknown, the file is a sequence, or the primitive
            that carries the descriptor is absent (adding one would change others too).
    """
    where = b.span
    if descriptor not in DESCRIPTOR_FIELDS:
        raise AouError(diag("I501", f"unknown descriptor `{descriptor}`: expected one of "
                            f"{', '.join(DESCRIPTOR_FIELDS)}", where))
    if b.form != "descriptor":
        raise AouError(diag("I501", "variants are made from descriptor-form files, where "
                            "each descriptor is set by one statement", where))
    kind, plane, field, scale = DESCRIPTOR_FIELDS[descriptor]
    prim = b.first(kind, plane)
    if prim is None:
        name = f"gaze {plane}" if plane else kind
        raise AouError(diag("I501", f"`{b.name}` has no `{name}` statement to vary; "
                            f"add one to the base first", where))
    out = []
    for label, value in (("low", low), ("high", high)):
        if scale is None:
            if value != int(value) or value < 0:
                raise AouError(diag("I501", f"{descriptor} is a count: expected a whole "
                                    f"number, found {value:g}", where))
            new = prim.model_copy(update={field: int(value)})
        else:
            new = prim.model_copy(update={field: value * scale})
        out.append(Variant(label, value, _replace(text, prim.span, format_primitive(new))))
    return out
