"""Which values to change to fit a behaviour to an arm (``--fit``), and by how much.

Where the arm cannot give a declared value, the compiler says so with the value that
fits (C304: the peak acceleration the joints allow; C308: the highest shiver frequency;
C309: the fastest tilt). :func:`plan` turns those into :class:`Change`s of the file's
text, by this rule:

- Change only what the arm refused, at the statement it refused; nothing else.
- A shiver's frequency is not one of the eleven descriptors: a shiver too fast is made
  slower (``f=``) at the same amplitude, and its ``for`` lengthened to the 3 cycles a
  shiver lasts at least (what the compiler would do anyway, said in the file). No
  descriptor changes.
- A descriptor the arm cannot reach (an acceleration, a tilt velocity) is compressed
  toward the arm's peak ``cap`` by one increasing map, :func:`compress`: values up to
  90 % of the peak stay, higher ones approach the peak without reaching it
  (``k + w d / (d + w)``, ``k`` 90 % of the peak, ``w`` the other 10 %, ``d`` how far the
  value is above ``k``). Two files
  that differ only in that value are fitted to values in the same order (the map is
  strictly increasing), so a Part B variant pair keeps its contrast.
- A value no key of the statement's kind sets (a gaze's acceleration: the language
  fixes it, and ``gaze`` takes no ``a=``) is never written: :func:`fixed` says so
  instead, as a typed refusal (:class:`~aou_dsl.fit.refusals.FixedByLanguage`).
- Fitted descriptors are written with 4 significant digits, a shiver's frequency with 3,
  rounded toward what fits.

The builder applies the changes, compiles again (a fitted value can land a little
off the arm's real peak; the rule is applied again from the declared value with the new
peak) and keeps the fit only when the file still expresses its declared state.
"""

from __future__ import annotations

from collections.abc import Mapping

from ..core.codes import C301, C302, C303, C304, C308, C309, C314
from ..core.diagnostics import Diagnostic, Span, refused
from ..lang.descriptors import REGISTRY
from ..lang.primitives import KINDS, TILT
from .refusals import AccelerationShort, FixedByLanguage, ShiverTooFast, TiltTooFast, answer_of
from .rounding import written
from .text_edits import Change, value_text

#: The descriptor a tilt's ``v=`` sets.
_TILT_VELOCITY = next(d.name for d in REGISTRY.values() if d.kind == TILT and d.ir_field == "v")

__all__ = ["FITTED", "KNEE", "compress", "fixed", "hint_edit", "plan", "shiver_keys"]

#: Fraction of the arm's peak below which a declared value is never changed.
KNEE = 0.9
#: The codes whose values :func:`plan` fits (a reach refusal by the changes the builder
#: found, its field ``reach``: :mod:`aou_dsl.fit.reach`).
FITTED = (C301, C302, C303, C304, C308, C309)


def compress(x: float, cap: float, knee: float = KNEE) -> float:
    """``x`` brought under ``cap`` by a strictly increasing map: unchanged up to
    ``knee * cap``, then approaching ``cap`` (never reaching it)."""
    k = knee * cap
    if x <= k:
        return x
    w, over = cap - k, x - k
    return k + w * over / (over + w)  # slope 1 at the knee, then ever flatter


def shiver_keys(f_ok: float, runs: float | None) -> list[tuple[str, str, str, str | None]]:
    """``(key, fitted, unit, descriptor)`` of a shiver made ``f_ok`` [Hz]: its frequency,
    and, when the statement says `for` (``runs`` [s], else None), one of the 3 cycles it
    then lasts at least."""
    f = written(f_ok, 3)
    out: list[tuple[str, str, str, str | None]] = [("f", f, "Hz", None)]
    if runs is not None and round(runs * float(f)) < 3:
        out.append(("for", written(3.0 / float(f), 3, "up"), "s", None))
    return out


def _shiver(r: ShiverTooFast) -> list[tuple[str, str, str, str | None]]:
    """``(key, fitted, unit, descriptor)`` of a shiver too fast: its highest frequency
    (one the compiler offers only when it still looks like a shiver), and, when the
    statement says `for`, one of the 3 cycles it then lasts at least."""
    if not r.max_frequency:
        return []
    return shiver_keys(r.max_frequency, r.duration)  # duration None: no `for`


def hint_edit(r: ShiverTooFast) -> str | None:
    """Every change a C308 needs, as one edit (``f=1.4Hz for 2.15s``)."""
    return " ".join(value_text(k, v, u) for k, v, u, _ in _shiver(r)) or None


#: The kind of each statement, by its ``(line, col)``.
Kinds = Mapping[tuple[int, int], str]


def _fixed(d: Diagnostic, kinds: Kinds) -> FixedByLanguage | None:
    """The record of ``d`` when it refuses a value its statement's kind takes no key for."""
    r, kind = d.refusal, kinds.get((d.span.line, d.span.col))
    if not isinstance(r, AccelerationShort) or kind is None or kind not in KINDS \
            or "a" in KINDS[kind].keys:
        return None
    unit = "m/s^2" if KINDS[kind].translation else "rad/s^2"
    return FixedByLanguage(kind, "a", tuple(KINDS[kind].keys), r.declared, r.achieved, unit,
                           r.joint)


def fixed(diagnostics: list[Diagnostic], kinds: Kinds) -> list[Diagnostic]:
    """A C314 for each value ``diagnostics`` refuse that the language fixes (no key of
    the statement's kind sets it, ``kinds`` by ``(line, col)``): why the fit leaves it."""
    out = []
    for d in diagnostics:
        r = _fixed(d, kinds)
        if r is None:
            continue
        takes = ", ".join(f"`{k}=`" for k in r.takes) or "no key"
        gives = "" if r.achieved is None else f"; the arm gives {r.achieved:.3g} {r.unit}" + (
            f" ({r.joint} binds)" if r.joint else "")
        value = "" if r.declared is None else f" ({r.declared:.3g} {r.unit})"
        out.append(refused(
            C314, f"not fitted: a {r.kind}'s acceleration is fixed by the language"
            f"{value}: `{r.kind}` takes {takes}, no `{r.key}=`, so the "
            f"fit writes none{gives}", d.span, r))
    return out


def plan(diagnostics: list[Diagnostic], declared: dict[tuple, float],
         kinds: Kinds | None = None) -> list[Change]:
    """The changes that fit what ``diagnostics`` refuse (their typed refusals, and the
    changes the reach and amplitude fits found). ``declared`` holds, by ``(line, col,
    key)`` of the statement, the value first declared where an earlier round changed it
    (the rule is applied from it, not from the fitted value). ``kinds`` gives each
    statement's kind by ``(line, col)``: a value its kind takes no key for is not
    changed (:func:`fixed`)."""
    out = []
    for d in diagnostics:
        r = d.refusal
        if _fixed(d, kinds or {}) is not None:
            continue
        if isinstance(r, AccelerationShort) and r.achieved and r.declared is not None:
            x = declared.get(_at(d, "a"), float(r.declared))
            fitted = written(compress(x, float(r.achieved)), 4)
            out.append(Change(d.span, "a", f"{x:g}", fitted, "", r.joint, "acceleration",
                              r.descriptor))
        elif isinstance(r, ShiverTooFast):
            was = {"f": r.f, "for": r.duration}
            for key, value, unit, desc in _shiver(r):
                w = was.get(key)
                out.append(Change(d.span, key, "" if w is None else f"{w:.3g}", value, unit,
                                  r.joint, r.limit, desc))
        elif isinstance(r, TiltTooFast) and r.max_velocity:
            v = declared.get(_at(d, "v"), r.declared_velocity)
            fitted = written(compress(float(v), r.max_velocity) if v else r.max_velocity, 4)
            out.append(Change(d.span, "v", "" if v is None else f"{v:g}", fitted, "deg/s",
                              r.joint, r.limit, _TILT_VELOCITY))
        # the changes the builder found (a reach, a shiver's amplitude: field ``reach``)
        out += [Change(Span(d.span.path, c["line"], c["col"], c["line"], c["end_col"]),
                       c["key"], c["declared"], c["fitted"], c["unit"], c["joint"],
                       c["limit"], c["descriptor"]) for c in answer_of(d).offered]
    return out


def _at(d: Diagnostic, key: str) -> tuple[int, int, str]:
    return d.span.line, d.span.col, key
