"""``aouc variants``: the study's Part B stimuli, pairs that differ in one descriptor.

From a descriptor-form file and ``NAME=LOW,HIGH``, two files are made that are the
original text with one value rewritten: the one that sets NAME (the descriptor table
says which statement, and which field). Only that value changes (a value the statement
leaves at its default is added as ``key=value``); comments, order and every other
statement stay byte for byte, so the pair differs in that descriptor only. A first line
``# written by `aouc variants` ...`` marks each file as aou's (it may be replaced
again without ``--force``); varying a variant replaces that line and keeps the base's
name (``a-pause_duration-low.aou`` varied again gives ``a-NAME-low.aou``). Values are in the
descriptor's unit (m, s, m/s^2, deg, deg/s; counts are whole numbers, a count of 1 is
written ``x1``). Both files must lint without errors and, read back, declare the value
they are named for, and the two must differ; or neither is returned.
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, replace

from ..core.codes import I504
from ..core.diagnostics import AouError, Span, diag
from ..lang.declared import source_of
from ..lang.descriptors import REGISTRY
from ..lang.ir import Behaviour
from ..lang.linter import lint_source
from ..lang.parse import KeyVal, Statement, parse
from ..lang.primitives import KINDS

__all__ = ["MARK", "Variant", "base_stem", "make_variants", "parse_vary"]

#: The first line of a variant: aou's mark (:func:`aou_dsl.core.files.is_own_output`).
MARK = "# written by `aouc variants`"


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
        raise AouError(diag(I504, f"--vary takes NAME=LOW,HIGH, e.g. "
                            f"pause_duration=1.0,2.5; found `{text}`", where)) from None
    if name not in REGISTRY:
        raise AouError(diag(I504, f"unknown descriptor `{name}`: expected one of "
                            f"{', '.join(REGISTRY)}", where))
    if not (math.isfinite(low) and math.isfinite(high)):
        raise AouError(diag(I504, f"--vary values must be finite numbers, found `{text}`",
                            where))
    return name, low, high


def base_stem(path: str) -> str:
    """The name variants of ``path`` are named after: its own, or for a variant
    (``a-pause_duration-low.aou``) its base's (``a``), so names do not stack."""
    stem = os.path.splitext(os.path.basename(path))[0]
    m = re.fullmatch(r"(.+)-([a-z_]+)-(low|high)", stem)
    return m.group(1) if m and m.group(2) in REGISTRY else stem


def _replace(text: str, span: Span, new: str) -> str:
    lines = text.splitlines(keepends=True)
    line = lines[span.line - 1]
    lines[span.line - 1] = line[:span.col - 1] + new + line[span.end_col - 1:]
    return "".join(lines)


def _statement(text: str, path: str) -> Statement:
    """The one statement of ``text``."""
    item = parse(text, path).items[0]
    assert isinstance(item, Statement)
    return item


def _rewrite(text: str, span: Span, old: str, new: str) -> str:
    """``text`` with the statement at ``span`` changed where the formatted statements
    ``old`` and ``new`` differ, and nowhere else: a changed ``key=value`` or positional
    value replaces the one written (or, when the file left it out, is added at the end)."""
    line = text.splitlines()[span.line - 1]
    written = _statement(line[span.col - 1:span.end_col - 1], "<statement>")
    a, b = _statement(old, "<old>"), _statement(new, "<new>")
    keyed = {x.key: x for x in written.args if isinstance(x, KeyVal)}
    plain = [x for x in written.args if not isinstance(x, KeyVal)]
    olds = {x.key: x for x in a.args if isinstance(x, KeyVal)}
    old_plain = [x for x in a.args if not isinstance(x, KeyVal)]
    edits: list[tuple[int, int, str]] = []  # columns in the statement, 1-based
    added: list[str] = []
    k = 0
    for x in b.args:
        src = new[x.span.col - 1:x.span.end_col - 1]
        if isinstance(x, KeyVal):
            same = x.key in olds and src == old[olds[x.key].span.col - 1:
                                                   olds[x.key].span.end_col - 1]
            if not same and x.key in keyed:
                edits.append((keyed[x.key].span.col, keyed[x.key].span.end_col, src))
            elif not same:
                added.append(src)
            continue
        was = old_plain[k] if k < len(old_plain) else None
        if was is None or src != old[was.span.col - 1:was.span.end_col - 1]:
            if k < len(plain):
                edits.append((plain[k].span.col, plain[k].span.end_col, src))
            else:
                added.append(src)
        k += 1
    stmt = line[span.col - 1:span.end_col - 1]
    for col, end, src in sorted(edits, reverse=True):
        stmt = stmt[:col - 1] + src + stmt[end - 1:]
    return _replace(text, span, " ".join([stmt, *added]))


def _marked(text: str, base: str, label: str, descriptor: str, value: float) -> str:
    """``text`` with aou's first line (replacing a variant's)."""
    if text.startswith(MARK):
        text = text.split("\n", 1)[1] if "\n" in text else ""
    return f"{MARK} from {base}: {descriptor}={value:g} ({label})\n{text}"


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
        raise AouError(diag(I504, "variants are made from descriptor-form files, where "
                            "each descriptor is set by one statement", where))
    prim = source_of(b, descriptor)
    if prim is None:
        raise AouError(diag(I504, f"`{b.name}` has no `{d.kind}` statement to vary; "
                            f"add one to the base first", where))
    out = []
    for label, value in (("low", low), ("high", high)):
        if d.is_count and (value != int(value) or value < 0):
            raise AouError(diag(I504, f"{descriptor} is a count: expected a whole number, "
                                f"found {value:g}", where))
        new = prim.replace(**{d.ir_field: int(value) if d.is_count else value * d.scale})
        formatted = KINDS[d.kind].format(new)
        if d.is_count and new.count == 1:  # the formatter leaves out a count of 1
            formatted += " x1"
        body = _rewrite(text, prim.span, KINDS[d.kind].format(prim), formatted)
        variant = Variant(label, value, _marked(body, os.path.basename(b.span.path), label,
                                                descriptor, value), f"{prefix}-{label}.aou")
        lint = lint_source(variant.text, variant.path)
        if not lint.ok:  # the variant's own errors (exit 1): nothing is written
            statement = KINDS[d.kind].format(new)
            raise AouError([  # said at the statement varied, in the file that exists
                replace(e, message=f"the {label} variant (`{statement}`, for "
                        f"{variant.path}) would not lint: {e.message}", span=prim.span)
                for e in lint.diagnostics if e.severity == "error"])
        _check_says(variant, lint.behaviour, descriptor, where)
        out.append(variant)
    if out[0].text.split("\n", 1)[1] == out[1].text.split("\n", 1)[1]:
        raise AouError(diag(I504, f"the low and high variants of {descriptor} would be the "
                            f"same file ({low:g} and {high:g} write the same text)", where,
                            hint="give two values that differ in the file's precision "
                                 "(six significant digits)"))
    return out


def _check_says(v: Variant, b: Behaviour | None, descriptor: str, where: Span) -> None:
    """Refuse a variant whose text, read back, does not declare ``descriptor`` as the
    value it reports (to the six digits it is reported with).

    Raises:
        AouError: I504 naming both values.
    """
    import math

    from ..lang.declared import written

    got = None if b is None else written(b)[descriptor]
    want = abs(v.value)
    if got is not None and (got == want if REGISTRY[descriptor].is_count else
                            math.isclose(abs(got), want, rel_tol=5e-6, abs_tol=1e-12)):
        return
    raise AouError(diag(I504, f"the {v.label} variant ({v.path}) would declare "
                        f"{descriptor}={'absent' if got is None else f'{got:g}'}, not the "
                        f"{v.value:g} asked for: nothing is written", where,
                        hint="vary a descriptor the file sets with one statement, to a "
                             "value the statement can take"))
