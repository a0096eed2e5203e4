"""Completion: keywords at the start of a statement, the keys each keyword takes, units
after a number, states after the header's ``:``, robots after ``robot``, planes after
``gaze``."""

from __future__ import annotations

import re

from lsprotocol import types

from ..core.robot_specs import ROBOTS
from ..core.units import UNITS, Dim, units_for
from ..lang.ir import State
from ..lang.primitives import KINDS
from ..lang.validate import KEYWORDS
from .state import Document
from .text import statement_at, tokens_of

__all__ = ["complete"]

_K = types.CompletionItemKind

#: The dimension of each keyword's positional quantity.
_POSITIONAL = {"pause": Dim.TIME, "retreat": Dim.LENGTH, "approach": Dim.LENGTH,
               "gaze": Dim.ANGLE, "tilt": Dim.ANGLE, "shiver": Dim.ANGLE,
               "start": Dim.LENGTH, "standoff": Dim.LENGTH}

_NUMBER = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")


def _items(words, kind, detail: str = "") -> list[types.CompletionItem]:
    return [types.CompletionItem(label=w, kind=kind, detail=detail or None) for w in words]


def _keys(keyword: str, written: set[str]) -> list[types.CompletionItem]:
    kind = KINDS.get(keyword)
    if kind is None:
        return []
    out = [types.CompletionItem(label=f"{k}=", kind=_K.Property, insert_text=f"{k}=",
                                detail=f"{spec.what} ({spec.bare_unit} when bare)")
           for k, spec in kind.keys.items() if k not in written]
    if keyword == "shiver" and "for" not in written:
        out.append(types.CompletionItem(label="for", kind=_K.Keyword,
                                        detail="for DURATION: how long it shivers"))
    if "[xN]" in kind.usage:
        out.append(types.CompletionItem(label="x2", kind=_K.Value, insert_text="x",
                                        detail="repeat count: xN episodes"))
    return out


def _units(keyword: str, key: str | None, number: str) -> list[types.CompletionItem]:
    kind = KINDS.get(keyword)
    if key and kind and key in kind.keys:
        dims = [kind.keys[key].dim]
    elif key == "for":
        dims = [Dim.TIME]
    elif keyword in _POSITIONAL:
        dims = [_POSITIONAL[keyword]]
    else:
        dims = list(Dim)
    units = [u for d in dims for u in units_for(d)]
    return [types.CompletionItem(label=f"{number}{u}", kind=_K.Unit, filter_text=f"{number}{u}",
                                 insert_text=f"{number}{u}", detail=str(UNITS[u][0]))
            for u in units]


def complete(doc: Document, pos: types.Position) -> types.CompletionList:
    li, col = doc.view.aou_at(pos)
    line = doc.lines[li]
    toks = tokens_of(line[:col])
    stmt = statement_at(toks, col)
    typing = stmt[-1] if stmt and stmt[-1].end == col else None
    before = stmt[:-1] if typing else stmt
    items: list[types.CompletionItem] = []
    if toks and toks[-1].kind == "comment":
        items = []
    elif not before:
        items = _items(KEYWORDS, _K.Keyword)
    elif typing is not None and typing.kind == "quantity" and _NUMBER.match(typing.text):
        key = before[-2].text if len(before) >= 2 and before[-1].text == "=" else (
            "for" if before[-1].text == "for" else None)
        items = _units(before[0].text, key, typing.text)
    else:
        items = _after(before, typing)
    return types.CompletionList(is_incomplete=False, items=items)


def _after(before, typing) -> list[types.CompletionItem]:
    keyword = before[0].text
    last = before[-1].text
    if keyword == "behaviour" and last == ":":
        return _items([s.value for s in State], _K.EnumMember, "state")
    if keyword == "robot" and len(before) == 1:
        return _items(ROBOTS, _K.Module, "built-in robot")
    if keyword == "gaze" and len(before) == 1:
        return _items(("horizontal", "vertical"), _K.EnumMember, "plane")
    if last == "=" or (typing is not None and typing.kind != "word"):
        return []
    written = {t.text for i, t in enumerate(before) if i + 1 < len(before)
               and before[i + 1].text == "="} | {t.text for t in before}
    return _keys(keyword, written)
