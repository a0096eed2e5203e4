"""Completion: keywords at the start of a statement, the keys each keyword takes, units
after a number, states after the header's ``:``, robots after ``robot``, planes after
``gaze``. What each kind takes beyond its kind object is :mod:`.kind_texts`'s."""

from __future__ import annotations

import re

from lsprotocol import types

from ..core.robot_specs import ROBOTS
from ..core.units import UNITS, Dim, units_for
from ..lang.ir import State
from ..lang.primitives import KINDS
from ..lang.validate import KEYWORDS
from .kind_texts import kind_texts, texts_of
from .state import Document
from .text import statement_at, tokens_of

__all__ = ["complete"]

_K = types.CompletionItemKind

#: The dimension of each setting's positional quantity (a kind's: :mod:`.kind_texts`).
_POSITIONAL = {"start": Dim.LENGTH, "standoff": Dim.LENGTH}

_NUMBER = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")


def _keywords() -> tuple[str, ...]:
    """The statement keywords: the language's, then any other kind (a plugin's)."""
    return (*KEYWORDS, *(k for k in KINDS if k not in KEYWORDS))


def _positional(keyword: str) -> Dim | None:
    texts = texts_of(keyword)
    return texts.positional if texts is not None else _POSITIONAL.get(keyword)


def _items(words, kind, detail: str = "") -> list[types.CompletionItem]:
    return [types.CompletionItem(label=w, kind=kind, detail=detail or None) for w in words]


def _keys(keyword: str, written: set[str]) -> list[types.CompletionItem]:
    kind = KINDS.get(keyword)
    if kind is None:
        return []
    out = [types.CompletionItem(label=f"{k}=", kind=_K.Property, insert_text=f"{k}=",
                                detail=f"{spec.what} ({spec.bare_unit} when bare)")
           for k, spec in kind.keys.items() if k not in written]
    texts = texts_of(keyword)
    for word, detail in (texts.words.items() if texts is not None else ()):
        if word not in written:
            out.append(types.CompletionItem(label=word, kind=_K.Keyword, detail=detail))
    if "[xN]" in kind.usage:
        out.append(types.CompletionItem(label="x2", kind=_K.Value, insert_text="x",
                                        detail="repeat count: xN episodes"))
    return out


def _units(keyword: str, key: str | None, number: str) -> list[types.CompletionItem]:
    kind = KINDS.get(keyword)
    if key and kind and key in kind.keys:
        dims = [kind.keys[key].dim]
    elif key and (word := _word_dim(keyword, key)) is not None:
        dims = [word]
    elif (positional := _positional(keyword)) is not None:
        dims = [positional]
    else:
        dims = list(Dim)
    units = [u for d in dims for u in units_for(d)]
    return [types.CompletionItem(label=f"{number}{u}", kind=_K.Unit, filter_text=f"{number}{u}",
                                 insert_text=f"{number}{u}", detail=str(UNITS[u][0]))
            for u in units]


def _word_dim(keyword: str, word: str) -> Dim | None:
    """The dimension of the quantity after ``word`` (a shiver's ``for``): the keyword's
    kind's, else any kind's that takes the word."""
    texts = texts_of(keyword)
    if texts is not None and word in texts.word_dims:
        return texts.word_dims[word]
    return next((t.word_dims[word] for t in kind_texts().values() if word in t.word_dims),
                None)


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
        items = _items(_keywords(), _K.Keyword)
    elif typing is not None and typing.kind == "quantity" and _NUMBER.match(typing.text):
        key = before[-2].text if len(before) >= 2 and before[-1].text == "=" else (
            before[-1].text if _word_dim(before[0].text, before[-1].text) else None)
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
    texts = texts_of(keyword)
    if texts is not None and texts.planes and len(before) == 1:
        return _items(texts.planes, _K.EnumMember, "plane")
    if last == "=" or (typing is not None and typing.kind != "word"):
        return []
    written = {t.text for i, t in enumerate(before) if i + 1 < len(before)
               and before[i + 1].text == "="} | {t.text for t in before}
    return _keys(keyword, written)
