"""Stage 2, validate: syntax tree -> :class:`~aou_dsl.lang.ir.Behaviour`, with diagnostics.

Every validity rule of the language lives here, so ``validate()`` and ``aouc lint``
agree. The validator reports every problem it can find in one pass (not just the
first), each with the span of the offending token: statements (:mod:`.reader` and each
kind's ``read``), settings (:mod:`.settings`), then the behaviour as a whole
(:mod:`.whole`: resource bounds, reach, and whether its layout shows what it declares).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import overload

from ..core.codes import V101, V107, V108, V111, V113, V114, V115
from ..core.diagnostics import Diagnostic, Span
from .ir import Behaviour, Node, State
from .layout import Laid
from .parse import Colon, SequenceBlock, Statement, SyntaxTree, Word
from .primitives import GAZE, KINDS, Timing, plugin_problems
from .settings import SETTINGS, read_settings
from .timeline import Timeline
from .values import Ctx, Reader, did_you_mean, fix_word
from .whole_file import MAX_EPISODES, MAX_MOTION_TIME, check_whole

__all__ = ["KEYWORDS", "MAX_EPISODES", "MAX_MOTION_TIME", "Validated", "primitive", "validate",
           "validate_tree"]



class _Keywords(Sequence[str]):
    """Every statement keyword: the header, the settings, every kind (the plugins' too,
    as :data:`KINDS` holds them now) and ``sequence``."""

    __slots__ = ()

    def _now(self) -> tuple[str, ...]:
        return ("behaviour", *SETTINGS, *KINDS, "sequence")

    @overload
    def __getitem__(self, i: int) -> str: ...
    @overload
    def __getitem__(self, i: slice) -> Sequence[str]: ...

    def __getitem__(self, i):
        return self._now()[i]

    def __len__(self) -> int:
        return len(self._now())

    def __iter__(self) -> Iterator[str]:
        return iter(self._now())

    def __contains__(self, word: object) -> bool:
        return word in self._now()


KEYWORDS: Sequence[str] = _Keywords()


@dataclass(frozen=True)
class Validated:
    """A validated file: the behaviour and its timeline (None on errors), diagnostics."""

    behaviour: Behaviour | None
    timeline: Timeline | None
    diagnostics: list[Diagnostic] = field(default_factory=list)


def primitive(ctx: Ctx, st: Statement, in_sequence: bool) -> Node | None:
    """A primitive statement as IR, or None (with diagnostics) when it does not fit."""
    kind = KINDS[st.keyword]
    # an oscillation lasts a number of swings, or `for DURATION`
    return kind.read(Reader(ctx, st, kind, in_sequence,
                            takes_for=kind.timing is Timing.OSCILLATION))


def _header(ctx: Ctx, st: Statement) -> tuple[str | None, State | None]:
    pos = list(st.args)
    if not pos or not isinstance(pos[0], Word):
        ctx.error(V113, "`behaviour` takes a name, e.g. `behaviour peek : curious`",
                  st.keyword_span)
        return None, None
    name, rest = pos[0].text, pos[1:]
    if not rest:
        return name, None
    if not isinstance(rest[0], Colon) or len(rest) != 2 or not isinstance(rest[1], Word):
        ctx.error(V113, "the header is `behaviour NAME : STATE`", rest[0].span)
        return name, None
    sw = rest[1]
    if sw.text not in State.__members__.values():
        ctx.error(V114, f"unknown state `{sw.text}`: expected one of "
                  f"{', '.join(s.value for s in State)}", sw.span,
                  hint=did_you_mean(sw.text, [s.value for s in State]), found=sw.text,
                  fix=fix_word(sw.span, sw.text, [s.value for s in State]))
        return name, None
    return name, State(sw.text)


@dataclass
class _File:
    """What the statements of a file say, sorted."""

    name: str | None = None
    state: State | None = None
    header: Span | None = None
    settings: list[Statement] = field(default_factory=list)
    descriptor: list[Node] = field(default_factory=list)
    sequence: list[Node] = field(default_factory=list)
    block: SequenceBlock | None = None
    first_primitive: Span | None = None
    seen: dict[str, Span] = field(default_factory=dict)
    #: How a primitive statement is read (:func:`primitive`, or a kept reading of it).
    read: Callable[[Ctx, Statement, bool], Node | None] = primitive


def _block(ctx: Ctx, f: _File, item: SequenceBlock) -> None:
    if f.block is not None:
        ctx.error(V111, f"a file has one `sequence` block; the first is at {f.block.span}",
                  item.span)
        return
    f.block = item
    for st in item.statements:
        if st.keyword not in KINDS:
            ctx.error(V101 if st.keyword not in KEYWORDS else V113,
                      f"`{st.keyword}` is not a primitive; a sequence holds only "
                      f"{', '.join(KINDS)}{_no_plugin(st.keyword)}", st.keyword_span,
                      hint=did_you_mean(st.keyword, KINDS),
                      fix=fix_word(st.keyword_span, st.keyword, KINDS))
            continue
        p = f.read(ctx, st, True)
        if p is not None:
            f.sequence.append(p)


def _descriptor_statement(ctx: Ctx, f: _File, st: Statement) -> None:
    f.first_primitive = f.first_primitive or st.span
    p = f.read(ctx, st, False)
    key = f"{GAZE} {getattr(p, 'plane', '')}" if p is not None and p.kind == GAZE \
        else st.keyword
    if key in f.seen:
        ctx.error(V107, f"`{key}` appears twice in the descriptor form (first at "
                  f"{f.seen[key]})", st.keyword_span,
                  hint="use `xN` for more episodes, or a `sequence { }` block for episodes "
                  "that differ")
        return
    f.seen[key] = st.span
    if p is not None:
        f.descriptor.append(p)


def _no_plugin(word: str) -> str:
    """Why no kind is called ``word``, for V101: no installed plugin gives it, or the one
    that does could not be used."""
    if word in KEYWORDS:
        return ""
    for p in plugin_problems():
        if p.name == word:
            return f" (the plugin that gives it cannot be used: {p.why})"
    return " (and no installed plugin gives it)"


def _statement(ctx: Ctx, f: _File, st: Statement, first: bool) -> None:
    if st.keyword == "behaviour":
        if f.header is not None:
            ctx.error(V111, f"the header is given twice (first at {f.header})",
                      st.keyword_span)
        elif not first:
            ctx.error(V115, "the `behaviour` header must be the first statement",
                      st.keyword_span)
        else:
            f.header = st.span
            f.name, f.state = _header(ctx, st)
    elif st.keyword in SETTINGS:
        f.settings.append(st)
    elif st.keyword in KINDS:
        _descriptor_statement(ctx, f, st)
    else:
        ctx.error(V101, f"unknown statement `{st.keyword}`{_no_plugin(st.keyword)}",
                  st.keyword_span,
                  hint=did_you_mean(st.keyword, KEYWORDS) or
                  f"statements are {', '.join(KEYWORDS)}", found=st.keyword,
                  fix=fix_word(st.keyword_span, st.keyword, KEYWORDS))


def validate_tree(tree: SyntaxTree,
                  read: Callable[[Ctx, Statement, bool], Node | None] | None = None,
                  laid: Laid | None = None) -> Validated:
    """Check a syntax tree, build the IR and lay it out. ``read(ctx, statement,
    in_sequence)`` reads a primitive statement as :func:`primitive` does, and ``laid``
    keeps the layout's episodes: the incremental linter passes both, to take again what
    the file's last lint made of the statements an edit left as they were."""
    ctx = Ctx(tree.path)
    f = _File(read=read or primitive)
    for i, item in enumerate(tree.items):
        if isinstance(item, SequenceBlock):
            _block(ctx, f, item)
        else:
            _statement(ctx, f, item, first=i == 0)
    if f.block is not None and f.first_primitive is not None:
        ctx.error(V108, "a file has either a `sequence { }` block or descriptor-form "
                  "primitives, not both", f.first_primitive,
                  hint=f"the sequence block is at {f.block.span}")
    settings = read_settings(ctx, f.settings)
    if ctx.has_errors():
        return Validated(None, None, ctx.diags)
    stem = tree.path.replace("\\", "/").rsplit("/", 1)[-1].removesuffix(".aou")
    behaviour = Behaviour(
        name=f.name or stem or "behaviour",
        state=f.state,
        form="sequence" if f.block is not None else "descriptor",
        settings=settings,
        primitives=tuple(f.sequence if f.block is not None else f.descriptor),
        span=Span(tree.path, 1, 1, 1, 1),
        header_span=f.header,
    )
    timeline = check_whole(ctx, behaviour, laid)
    if ctx.has_errors():
        return Validated(None, None, ctx.diags)
    return Validated(behaviour, timeline, ctx.diags)


def validate(tree: SyntaxTree) -> tuple[Behaviour | None, list[Diagnostic]]:
    """Check a syntax tree and build the IR.

    Returns:
        ``(behaviour, diagnostics)``; ``behaviour`` is None when any error was found.
    """
    v = validate_tree(tree)
    return v.behaviour, v.diagnostics
