"""Hover: a diagnostic's rule, a descriptor's meaning and what the study found of it,
the header's C-V point, and the episodes a statement lays out."""

from __future__ import annotations

import math
import re

from lsprotocol import types

from ..core.rule_model import Category
from ..lang.descriptors import DEFINITIONS, REGISTRY, Descriptor, every_descriptor
from ..lang.ir import State
from ..lang.primitives import KINDS
from . import lsp_engine as engine
from .kind_texts import definition, texts_of
from .state import Document
from .text import Tok, at, statement_at, tokens_of

__all__ = ["descriptor_for", "describe", "hover"]

#: A rule code named in a comment: any category's letter and three digits.
_CODE = re.compile(rf"\b[{''.join(c.value for c in Category)}]\d{{3}}\b")
_WAYS = {"": ("more", "fewer"), "s": ("longer", "shorter"), "m": ("longer", "shorter"),
         "deg": ("larger", "smaller")}
_STATES = (State.CONFIDENT, State.CURIOUS, State.HESITANT, State.FEARFUL)


def _markdown(text: str, rng: types.Range | None = None) -> types.Hover:
    return types.Hover(types.MarkupContent(types.MarkupKind.Markdown, text), rng)


def rule_text(code: str) -> str | None:
    """``aouc rules CODE``'s text."""
    r = engine.rule(code)
    if r is None:
        return None
    example = "\n".join(f"    {ln}" for ln in r.example.splitlines())
    return (f"**{r.code}** {r.name} [{r.severity}]\n\nwhat: {r.what}\n\nwhy: {r.why}\n\n"
            f"example:\n\n{example}")


def descriptor_for(keyword: str, slot: str, plane: str | None = None) -> Descriptor | None:
    """The descriptor a statement's argument sets: ``slot`` is a key (``a``), ``x``
    (the count) or ``value`` (the positional quantity)."""
    kind = KINDS.get(keyword)
    if kind is None:
        return None
    texts = texts_of(keyword)
    by_plane = texts is not None and bool(texts.planes)
    for d in every_descriptor().values():
        if d.kind != keyword or (by_plane and d.key != plane):
            continue
        if slot == "x" and d.is_count:
            return d
        if slot == d.ir_field and slot in kind.keys:
            return d
        if slot == "value" and not d.is_count and d.ir_field not in kind.keys:
            return d
    return None


def describe(d: Descriptor) -> str:
    """Name, unit, definition and what the study found the descriptor does."""
    unit = d.unit or "a count"
    found = []
    for s in _STATES:
        if s in d.no_effect:
            found.append(f"- {s}: no clear effect")
        elif d.stronger.get(s):
            up, down = _WAYS.get(d.unit, ("higher", "lower"))
            way = up if d.stronger[s] > 0 else down
            found.append(f"- {s}: looks more {s} as it is {way}")
    meaning = DEFINITIONS.get(d.name) or definition(d.name, d.kind)
    if d.name not in REGISTRY:  # a plugin's: the study never showed it to anyone
        return (f"**{d.name}** ({unit}): {meaning}.\n\nNot one of the eleven descriptors "
                "the study varied: no perceived effect is known.")
    study = "\n".join(found) or "- the study found no effect of it on any state"
    return (f"**{d.name}** ({unit}): {meaning}.\n\n"
            f"What the study found (one descriptor varied at a time):\n\n{study}")


def _key_text(keyword: str, key: str) -> str | None:
    kind = KINDS.get(keyword)
    spec = kind.keys.get(key) if kind else None
    if spec is None:
        return None
    return f"`{key}=`: the {spec.what} of `{keyword}` ({spec.dim}; a bare number is " \
           f"{spec.bare_unit})\n\nusage: `{kind.usage}`"  # type: ignore[union-attr]


def _argument(stmt: list[Tok], tok: Tok) -> str | None:
    """Hover on an argument: the descriptor it sets, or its key's meaning."""
    keyword = stmt[0].text
    texts = texts_of(keyword)
    planes = texts.planes if texts is not None else ()
    plane = next((t.text for t in stmt if t.text in planes), None)
    i = stmt.index(tok)
    if tok.text == "=" and i >= 1:
        tok, i = stmt[i - 1], i - 1
    slot = None
    if i + 1 < len(stmt) and stmt[i + 1].text == "=":
        slot = tok.text
    elif i >= 2 and stmt[i - 1].text == "=":
        slot = stmt[i - 2].text
    elif tok.kind == "word" and re.fullmatch(r"x\d+", tok.text):
        slot = "x"
    elif tok.kind == "quantity" and (i == 0 or stmt[i - 1].text != "for"):
        slot = "value"
    if slot is None:
        return None
    d = descriptor_for(keyword, slot, plane)
    if d is not None:
        return describe(d)
    return _key_text(keyword, slot) if slot not in ("x", "value") else None


def _header(doc: Document) -> str:
    lint = doc.lint
    if lint is None or lint.cv is None:
        return "`behaviour NAME : STATE`: the C-V point shows once the file has no errors"
    b, cv = lint.behaviour, lint.cv
    declared = f"declared `{b.state}`" if b and b.state else "no state declared"
    return (f"**{b.name if b else ''}**: C={cv.C:+.2f}, V={cv.V:+.2f}: the primitives "
            f"express `{cv.state}` ({declared})")


def _episodes(doc: Document, line: int, stmt: list[Tok]) -> str | None:
    kind = KINDS.get(stmt[0].text)
    if kind is None:
        return None
    first, last = stmt[0].start + 1, stmt[-1].end + 1

    def mine(span) -> bool:
        return span.line == line and first <= span.col and span.end_col <= last

    built = doc.compiled
    rows = []
    if built is not None and built.episodes:
        source = "compiled"
        for s in built.episodes:
            if mine(s.episode.span):
                rows.append(f"- {s.episode.kind} at {s.t_start:.2f} s for {s.duration:.2f} s: "
                            f"peak speed {s.peak_speed:.3f} m/s, peak acceleration "
                            f"{s.peak_acceleration:.3f} m/s^2")
    elif doc.lint is not None and doc.lint.timeline is not None:
        source = "laid out (compile figures after a save)"
        t = 0.0
        for ep in doc.lint.timeline.episodes:
            if mine(ep.span):
                rows.append(f"- {ep.kind} at {t:.2f} s for {ep.duration:.2f} s{_planned(ep)}")
            t += ep.duration
    else:
        return f"usage: `{kind.usage}`"
    body = "\n".join(rows) or "- no episode (x0)"
    return f"usage: `{kind.usage}`\n\nepisodes, {source}:\n\n{body}"


def _planned(ep) -> str:
    texts = texts_of(ep.kind)
    if texts is not None and texts.planned is not None:
        return texts.planned(ep)
    if not ep.moving:
        return ""
    peak = min(ep.vmax, math.sqrt(ep.a * ep.path_length)) if ep.a > 0 else ep.vmax
    if KINDS[ep.kind].translation:
        return f": peak speed {peak:.3f} m/s, acceleration {ep.a:.3g} m/s^2"
    return f": peak {math.degrees(peak):.3g} deg/s"


def hover(doc: Document, pos: types.Position) -> types.Hover | None:
    li, col = doc.view.aou_at(pos)
    line = doc.lines[li]
    codes = [d.code for d in doc.diagnostics if d.span.path == doc.path
             and (d.span.line, d.span.col - 1) <= (li + 1, col) <= (d.span.end_line,
                                                                   d.span.end_col - 1)]
    toks = tokens_of(line)
    tok = at(toks, col)
    if tok is not None and tok.kind == "comment":
        codes += [m.group(0) for m in _CODE.finditer(tok.text)]
    texts = [t for c in dict.fromkeys(codes) if (t := rule_text(c))]
    stmt = statement_at(toks, col)
    rng = None
    if tok is not None and stmt and tok in stmt:
        start = doc.view.aou_starts[li]
        rng = types.Range(doc.view.position(start + tok.start),
                          doc.view.position(start + tok.end))
        if stmt[0].text == "behaviour":
            texts.insert(0, _header(doc))
        elif (text := _episodes(doc, li + 1, stmt) if tok is stmt[0]
              else _argument(stmt, tok)):
            texts.insert(0, text)
    return _markdown("\n\n---\n\n".join(texts), rng) if texts else None
