"""``aouc variants``: the study's Part B stimuli, pairs that differ in one descriptor.

From a descriptor-form file and ``NAME=LOW,HIGH``, two files are made that are the
original text with one statement rewritten: the one that sets NAME (the descriptor
table says which, and which field). Comments, order and every other statement stay
byte for byte, so the pair differs in that descriptor only. Values are in the
descriptor's unit (m, s, m/s^2, deg, deg/s; counts are whole numbers). Both files must
lint without errors, or neither is returned.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..core.diagnostics import AouError, Span, diag
from ..lang.declared import source_of
from ..lang.descriptors import REGISTRY
from ..lang.ir import Behaviour
from ..lang.linter import lint_source
from ..lang.primitives import KINDS

__all__ = ["Variant", "make_variants", "parse_vary"]


@dataclass(frozen=True)
class Variant:
    label: str  # "low" or "high"
    value: float
    text: str
    path: str


def parse_vary(text: str) -> tuple[str, float, float]:
    """``NAME=LOW,HIGH`` -> (name, low, high).

    Raises:
        AouError: I501 when it is malformed or names no descriptor.
    """
    import math

    where = Span.whole_file("--vary")
    try:
        name, values = text.split("=", 1)
        low, high = (float(v) for v in values.split(","))
    except ValueError:
        raise AouError(diag("I504", f"--vary takes NAME=LOW,HIGH, e.g. "
                            f"pause_duration=1.0,2.5; found `{text}`", where)) from None
    if name not in REGISTRY:
        raise AouError(diag("I504", f"unknown descriptor `{name}`: expected one of "
                            f"{', '.join(REGISTRY)}", where))
    if not (math.isfinite(low) and math.isfinite(high)):
        raise AouError(diag("I504", f"--vary values must be finite numbers, found `{text}`",
                            where))
    return name, low, high


def _replace(text: str, span: Span, new: str) -> str:
    lines = text.splitlines(keepends=True)
    line = lines[span.line - 1]
    lines[span.line - 1] = line[:span.col - 1] + new + line[span.end_col - 1:]
    return "".join(lines)


def make_variants(b: Behaviour, text: str, descriptor: str, low: float, high: float,
                  prefix: str) -> list[Variant]:
    """The low and high variants of ``b`` (parsed from ``text``) in one descriptor,
    to be written to ``{prefix}-low.aou`` and ``{prefix}-high.aou``.

    Raises:
        AouError: the file is a sequence, the statement that carries the descriptor is
            absent (adding one would change others too), or a variant is not valid.
    """
    where = b.span
    d = REGISTRY[descriptor]
    if b.form != "descriptor":
        raise AouError(diag("I504", "variants are made from descriptor-form files, where "
                            "each descriptor is set by one statement", where))
    prim = source_of(b, descriptor)
    if prim is None:
        raise AouError(diag("I504", f"`{b.name}` has no `{d.kind}` statement to vary; "
                            f"add one to the base first", where))
    out = []
    for label, value in (("low", low), ("high", high)):
        if d.is_count and (value != int(value) or value < 0):
            raise AouError(diag("I504", f"{descriptor} is a count: expected a whole number, "
                                f"found {value:g}", where))
        new = prim.replace(**{d.ir_field: int(value) if d.is_count else value * d.scale})
        variant = Variant(label, value, _replace(text, prim.span, KINDS[d.kind].format(new)),
                          f"{prefix}-{label}.aou")
        lint = lint_source(variant.text, variant.path)
        if not lint.ok:  # the variant's own errors (exit 1): nothing is written
            statement = KINDS[d.kind].format(new)
            raise AouError([  # said at the statement varied, in the file that exists
                replace(e, message=f"the {label} variant (`{statement}`, for "
                        f"{variant.path}) would not lint: {e.message}", span=prim.span)
                for e in lint.diagnostics if e.severity == "error"])
        out.append(variant)
    return out
