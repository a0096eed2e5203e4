"""A study file (``study.toml``): what a perception study shows and asks, read strictly.

The file is untrusted like every input: read as a regular file of bounded size, parsed
by ``tomllib`` (data only), and every key checked for its type and range. An unknown key,
a missing table or a wrong value is E701 at the key's line; a behaviour that is missing
or does not lint clean is E702. Paths are relative to the study file.

The defaults are the paper's design: Part A shows the behaviours together, looping, and
asks for a description in the participant's words, the state among confident, curious,
hesitant and fearful (plus "Others", with a text, and "None") and its intensity on five
points; Part B shows base and variant side by side and asks which looks more like the
base's state: the low variant, the high variant, both equally, or neither.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from dataclasses import dataclass, field

from ..core.codes import E701, E702
from ..core.diagnostics import AouError, Span, diag
from ..core.inputs import read_input_text
from ..lang.descriptors import REGISTRY
from ..lang.ir import State

__all__ = ["PART_B_OPTIONS", "Pair", "Stimulus", "Study", "read_study"]

#: Part B's four answers, in the order the page offers them (the paper's).
PART_B_OPTIONS = ("low", "high", "both", "neither")
#: The model's five states, in its table's order.
STATES = tuple(s.value for s in State)
#: The most behaviours Part A shows, and the most pairs Part B asks about.
MAX_PART_A, MAX_PAIRS = 12, 200


@dataclass(frozen=True)
class Stimulus:
    """A Part A behaviour: its blind id (``A1``...), file and the state it declares."""

    id: str
    path: str
    state: str | None


@dataclass(frozen=True)
class Pair:
    """A Part B pair: its blind id (``B1``...), the base behaviour, the descriptor varied
    and its low and high values (in the descriptor's unit)."""

    id: str
    path: str
    state: str | None
    descriptor: str
    low: float
    high: float


@dataclass(frozen=True)
class Study:
    """A study file, checked. ``options``: Part A's answers (states, then ``others``
    and ``none`` when offered)."""

    path: str
    title: str
    robot: str
    seed: int
    part_a: tuple[Stimulus, ...]
    states: tuple[str, ...]
    others: bool
    none: bool
    intensity: int
    pairs: tuple[Pair, ...]
    texts: dict[str, str] = field(default_factory=dict)
    demographics: tuple[str, ...] = ()
    attention: tuple[dict, ...] = ()
    completion: dict[str, str] = field(default_factory=dict)
    render: dict[str, float] = field(default_factory=dict)

    @property
    def options(self) -> tuple[str, ...]:
        return self.states + (("others",) if self.others else ()) + \
            (("none",) if self.none else ())


class _Reader:
    """Checks one study file's values, each error E701 at its key's line."""

    def __init__(self, path: str, text: str):
        self.path, self.lines = path, text.split("\n")

    def where(self, key: str) -> Span:
        name = key.rsplit(".", 1)[-1]
        pat = re.compile(rf"^\s*(\[+\s*)?{re.escape(name)}\s*(=|\])")
        for i, line in enumerate(self.lines, 1):
            if pat.match(line):
                return Span(self.path, i, 1, i, len(line) + 1)
        return Span.whole_file(self.path)

    def fail(self, key: str, message: str) -> AouError:
        return AouError(diag(E701, f"`{key}`: {message}", self.where(key)))

    def table(self, data: dict, key: str, allowed: set[str], required: bool = False) -> dict:
        t = data.get(key.rsplit(".", 1)[-1], None if required else {})
        if not isinstance(t, dict):
            raise self.fail(key, "expected a table" if t is not None else "missing")
        unknown = sorted(set(t) - allowed)
        if unknown:
            raise self.fail(f"{key}.{unknown[0]}", f"not a key of [{key}] (it has "
                            f"{', '.join(sorted(allowed))})")
        return t

    def get(self, t: dict, key: str, kind: type | tuple, default=None, *, lo=None, hi=None):
        name = key.rsplit(".", 1)[-1]
        if name not in t:
            if default is None:
                raise self.fail(key, "missing")
            return default
        v = t[name]
        kinds = kind if isinstance(kind, tuple) else (kind,)
        if isinstance(v, bool) and bool not in kinds or not isinstance(v, kinds):
            names = " or ".join(k.__name__ for k in kinds)
            raise self.fail(key, f"expected {names}, found {type(v).__name__}")
        if isinstance(v, float) and not math.isfinite(v):
            raise self.fail(key, f"expected a finite number, found {v}")
        if isinstance(v, int | float) and not isinstance(v, bool) and (
                lo is not None and v < lo or hi is not None and v > hi):
            raise self.fail(key, f"expected a value in [{lo}, {hi}], found {v}")
        if isinstance(v, str) and len(v) > 20_000:
            raise self.fail(key, "a text of more than 20,000 characters")
        return v

    def strings(self, t: dict, key: str, default: tuple = (), most: int = 100) -> tuple:
        v = self.get(t, key, list, list(default))
        if len(v) > most or not all(isinstance(s, str) and len(s) <= 2000 for s in v):
            raise self.fail(key, f"expected a list of at most {most} texts")
        return tuple(v)


def _behaviour(path: str, base: str, where: Span) -> tuple[str, str | None]:
    """A stimulus's path (relative to the study file) and its declared state, linted."""
    from ..lang.linter import lint_file

    full = os.path.normpath(os.path.join(base, path))
    r = lint_file(full)
    errors = [d for d in r.diagnostics if d.severity == "error"]
    if errors:
        raise AouError(diag(E702, f"`{path}` cannot be shown: {errors[0].code} "
                            f"{errors[0].message}", where))
    return full, r.behaviour.state if r.behaviour else None


def _attention(rd: _Reader, table: dict, checks: list) -> tuple[dict, ...]:
    """``[attention] checks``: each a table of ``question``, ``options`` (2 to 10 texts)
    and ``answer`` (one of them)."""
    if set(table) - {"checks"}:
        raise rd.fail("attention", "expected only `checks`")
    out = []
    for i, c in enumerate(checks, 1):
        if not isinstance(c, dict) or set(c) != {"question", "options", "answer"}:
            raise rd.fail("attention.checks", f"check {i}: expected a table of question, "
                          "options and answer")
        q = rd.get(c, "attention.checks.question", str)
        opts = rd.strings(c, "attention.checks.options", most=10)
        a = rd.get(c, "attention.checks.answer", str)
        if len(opts) < 2 or a not in opts:
            raise rd.fail("attention.checks", f"check {i}: expected two options or more, "
                          "the answer one of them")
        out.append({"question": q, "options": list(opts), "answer": a})
    return tuple(out)


def read_study(path: str) -> Study:
    """The study file at ``path``, checked (E701, E702; I501 when it cannot be read)."""
    text = read_input_text(path, "study")
    rd = _Reader(path, text)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = int(m.group(1)) if (m := re.search(r"line (\d+)", str(exc))) else 1
        raise AouError(diag(E701, f"not TOML: {exc}", Span(path, line, 1, line, 2))) from None
    unknown = sorted(set(data) - {"study", "render", "texts", "part_a", "part_b",
                                  "attention", "completion"})
    if unknown:
        raise rd.fail(unknown[0], "not a table of a study file")
    s = rd.table(data, "study", {"title", "robot", "seed"}, required=True)
    a = rd.table(data, "part_a", {"behaviours", "states", "others", "none", "intensity"},
                 required=True)
    b = rd.table(data, "part_b", {"pairs"})
    texts = rd.table(data, "texts", {"consent", "instructions_a", "instructions_b",
                                     "demographics", "end"})
    render = rd.table(data, "render", {"width", "height", "fps"})
    base = os.path.dirname(os.path.abspath(path))
    states = rd.strings(a, "part_a.states", ("confident", "curious", "hesitant", "fearful"))
    bad = [x for x in states if x not in STATES]
    if bad or not states or len(set(states)) != len(states):
        raise rd.fail("part_a.states", f"expected distinct states of {', '.join(STATES)}")
    files = rd.strings(a, "part_a.behaviours", most=MAX_PART_A)
    part_a = tuple(Stimulus(f"A{i}", *_behaviour(f, base, rd.where("part_a.behaviours")))
                   for i, f in enumerate(files, 1))
    raw_pairs = rd.get(b, "part_b.pairs", list, [])
    if len(raw_pairs) > MAX_PAIRS:
        raise rd.fail("part_b.pairs", f"more than {MAX_PAIRS} pairs")
    pairs = []
    for i, p in enumerate(raw_pairs, 1):
        if not isinstance(p, dict) or set(p) - {"behaviour", "descriptor", "low", "high"}:
            raise rd.fail("part_b.pairs", f"pair {i}: expected a table of behaviour, "
                          "descriptor, low and high")
        d = rd.get(p, "part_b.pairs.descriptor", str)
        if d not in REGISTRY:
            raise rd.fail("part_b.pairs", f"pair {i}: `{d}` is not a descriptor")
        low = rd.get(p, "part_b.pairs.low", (int, float))
        high = rd.get(p, "part_b.pairs.high", (int, float))
        if not low < high:
            raise rd.fail("part_b.pairs", f"pair {i}: low ({low}) must be below high ({high})")
        full, state = _behaviour(rd.get(p, "part_b.pairs.behaviour", str), base,
                                 rd.where("part_b.pairs"))
        pairs.append(Pair(f"B{i}", full, state, d, float(low), float(high)))
    attention = rd.get(data, "attention", dict, {})
    checks = rd.get(attention, "attention.checks", list, []) if attention else []
    completion = rd.table(data, "completion", {"code", "redirect"})
    return Study(
        path=path, title=rd.get(s, "study.title", str, "A robot's motion"),
        robot=rd.get(s, "study.robot", str, "panda"),
        seed=rd.get(s, "study.seed", int, 1, lo=0, hi=2**63 - 1),
        part_a=part_a, states=states, others=rd.get(a, "part_a.others", bool, True),
        none=rd.get(a, "part_a.none", bool, True),
        intensity=rd.get(a, "part_a.intensity", int, 5, lo=2, hi=11), pairs=tuple(pairs),
        texts={k: rd.get(texts, f"texts.{k}", str) for k in texts if k != "demographics"},
        demographics=rd.strings(texts, "texts.demographics"),
        attention=_attention(rd, attention, checks),
        completion={k: rd.get(completion, f"completion.{k}", str) for k in completion},
        render={k: rd.get(render, f"render.{k}", (int, float), lo=1, hi=4096)
                for k in render})
