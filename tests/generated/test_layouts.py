"""Descriptor-form layouts against arrangements built from the kinds' needs.

Nothing here reads the layout's code. What a kind needs around it is the kind's own
property (``KINDS[kind].needs``: a retreat a pause before and after it, a gaze a pause
after it, pauses motion between them); from it and the descriptors' definitions:

- a generator hand-builds an arrangement (a list of episodes) that shows every
  descriptor, and writes the descriptor-form file it is one arrangement of: lint must
  accept it without V121, and it compiles and measures as declared;
- a brute force tries every arrangement of a small file: V121 appears exactly when it
  finds none.
"""

from __future__ import annotations

import functools
import random

import pytest

from aou_dsl import api
from aou_dsl.lang.descriptors import REGISTRY, compare
from aou_dsl.lang.primitives import APPROACH, GAZE, KINDS, PAUSE, RETREAT, SHIVER, TILT

#: An episode of the arrangement: its kind and, for a gaze, its plane.
P, A = (PAUSE, None), (APPROACH, None)
GH, GV = (GAZE, "horizontal"), (GAZE, "vertical")
R, T, S = (RETREAT, None), (TILT, None), (SHIVER, None)
MOTIONS = (R, GH, GV, T, S)


def _needs(token):
    return KINDS[token[0]].needs


def _every(token) -> bool:
    """Every episode of the kind must count: it has a count among the descriptors (a
    retreat); else one counting episode per plane shows its value (a gaze's angle)."""
    return any(d.is_count for d in REGISTRY.values() if d.kind == token[0])


def _away(token) -> bool:
    """It moves away from the goal: after the last approach the reach would not end at
    the standoff."""
    return KINDS[token[0]].translation and token[0] != APPROACH


# --- the brute force -------------------------------------------------------------------


def arrangement_exists(motions: dict, n_pauses: int, approach: bool) -> bool:
    """Whether any arrangement of the episodes shows every descriptor: ``motions`` maps
    each token to its number of episodes; approach pieces may go anywhere (at least one
    when the file has an approach, none otherwise; two never touch, nothing moves away
    after the last one). Shows every descriptor: no two pauses touch, every episode of a
    kind with a count counts, and each gaze plane has a gaze that counts."""
    tokens = sorted(motions, key=str)
    groups = frozenset(t for t in tokens if not _every(t) and _needs(t).around)

    @functools.cache
    def go(left, pauses, last, owed, seen, away, pieces) -> bool:
        if not any(left) and not pauses and owed is None and seen == groups \
                and (not approach or (pieces and not away)):
            return True
        options = [(t, i) for i, t in enumerate(tokens) if left[i]]
        options += [(P, -1)] if pauses else []
        options += [(A, -2)] if approach and last != A else []
        for t, i in options:
            if owed is not None and t[0] != owed:
                continue  # the last episode needs this kind after it
            needs = _needs(t)
            if needs.apart and last == t:
                continue
            if i >= 0 and _every(t) and needs.preceded_by is not None and \
                    (last is None or last[0] != needs.preceded_by):
                continue
            done = seen
            if last in groups and _needs(last).met(None, t[0]):
                done = seen | {last}
            rest = list(left)
            if i >= 0:
                rest[i] -= 1
            if go(tuple(rest), pauses - (t == P), t,
                  needs.followed_by if i >= 0 and _every(t) else None, done,
                  False if t == A else (away or _away(t)), pieces or t == A):
                return True
        return False

    return go(tuple(motions[t] for t in tokens), n_pauses, None, None, frozenset(),
              False, False)


# --- files ------------------------------------------------------------------------------

STATES = ["confident", "curious", "hesitant", "fearful", "inactive"]


def _file(motions: dict, n_pauses: int, approach: bool, state: str | None,
          rng: random.Random, name: str = "gen") -> str:
    """The descriptor-form file of these episode counts (values drawn where the
    language's round trip holds)."""
    lines = [f"behaviour {name}" + (f" : {state}" if state else ""),
             "start 0.34m", "standoff 12cm"]
    if approach:
        lines.append(f"approach a={rng.uniform(0.08, 0.3):.3g}")
    if n_pauses:
        lines.append(f"pause {rng.uniform(0.4, 1.2):.3g}s x{n_pauses}")
    if motions.get(R):
        lines.append(f"retreat {rng.uniform(0.02, 0.04):.3g}m a={rng.uniform(0.1, 0.5):.3g}"
                     f" x{motions[R]}")
    for token, plane, most in ((GH, "horizontal", 20), (GV, "vertical", 12)):
        if motions.get(token):
            lines.append(f"gaze {plane} {rng.uniform(6, most):.3g}deg x{motions[token]}")
    if motions.get(T):
        lines.append(f"tilt {rng.uniform(8, 20):.3g}deg v={rng.uniform(10, 20):.3g}deg/s"
                     f" x{motions[T]}")
    if motions.get(S):
        lines.append(f"shiver {rng.uniform(2, 5):.3g}deg f={rng.uniform(1.5, 2.5):.2g}Hz "
                     f"for 1.5s x{motions[S]}")
    return "\n".join(lines) + "\n"


def hand_built(rng: random.Random) -> tuple[list, dict, int, bool]:
    """An arrangement that shows every descriptor, built from the kinds' needs: the
    episodes in a random order, a pause put wherever a kind needs one (before and after
    each episode of a kind that counts only between pauses; after the first episode of
    each plane of a kind whose value a pause reads), more pauses at random where no pause
    is yet, approach pieces at random between and a last one at the end."""
    approach = rng.random() < 0.75
    episodes = [t for t in MOTIONS for _ in range(rng.choice((0, 0, 1, 2, 3)))]
    rng.shuffle(episodes)
    out: list = []
    ended: set = set()

    def pause() -> None:
        if not out or out[-1] != P:
            out.append(P)

    for t in episodes:
        needs = _needs(t)
        if needs.preceded_by == PAUSE:
            pause()
        elif approach and out and out[-1] != A and rng.random() < 0.4:
            out.append(A)
        out.append(t)
        if needs.followed_by == PAUSE and (_every(t) or t not in ended):
            pause()
            ended.add(t)
        elif rng.random() < 0.2:
            pause()
    if approach:
        if A not in out or any(_away(t) for t in out[len(out) - out[::-1].index(A):]):
            out.append(A)
        if rng.random() < 0.6:
            pause()
    if not out:
        out.append(P)
    motions = {t: episodes.count(t) for t in MOTIONS if t in episodes}
    return out, motions, out.count(P), approach


def _lint(text: str):
    return api.lint(source=text, path="gen.aou")


def _codes(result) -> list[str]:
    return [d.code for d in result.diagnostics if d.severity.value == "error"]


def _shows_its_descriptors(text: str) -> None:
    result = _lint(text)
    assert _codes(result) == [], (text, [d.message for d in result.diagnostics])


# --- the generator: hand-built arrangements ---------------------------------------------


#: Arrangements written out by hand, with the state whose file they show: three vertical
#: gazes, the last ending at the pause that starts the retreats (the layout once turned
#: one gaze to where the one before it stood and refused the file).
BY_HAND = [
    ("curious", [GV, A, GV, A, GV, P, R, P, R, P, A]),
    ("inactive", [GV, A, GV, A, GV, P, R, P, R, P, A, T, A]),
]


def _from_arrangement(state: str, arrangement: list, rng: random.Random) -> str:
    motions = {t: arrangement.count(t) for t in MOTIONS if t in arrangement}
    assert arrangement_exists(motions, arrangement.count(P), A in arrangement)
    return _file(motions, arrangement.count(P), A in arrangement, state, rng)


def _hand_built_files(n: int, seed: int) -> list[tuple[str, list]]:
    rng = random.Random(seed)
    out = [(_from_arrangement(state, arrangement, rng), arrangement)
           for state, arrangement in BY_HAND]
    for i in range(n):
        arrangement, motions, n_pauses, approach = hand_built(rng)
        assert arrangement_exists(motions, n_pauses, approach), arrangement
        text = _file(motions, n_pauses, approach, rng.choice([None, *STATES]), rng,
                     f"gen{i}")
        out.append((text, arrangement))
    return out


@pytest.mark.parametrize(("text", "arrangement"), _hand_built_files(40, 38))
def test_hand_built_arrangements_lint_without_v121(text, arrangement):
    _shows_its_descriptors(text)


def _round_trip(text: str) -> None:
    res = api.compile(source=text, path="gen.aou", check=False)
    assert res.ok, (text, [(d.code, d.message) for d in res.diagnostics])
    declared = res.document["descriptors"]["declared"]
    assert compare(declared, res.measured.descriptors) == [], text


@pytest.mark.parametrize(("text", "arrangement"), _hand_built_files(12, 5))
def test_hand_built_arrangements_compile_and_measure_as_declared(text, arrangement):
    _shows_its_descriptors(text)
    _round_trip(text)


@pytest.mark.large
@pytest.mark.parametrize(("text", "arrangement"), _hand_built_files(80, 77))
def test_more_hand_built_arrangements_compile_and_measure_as_declared(text, arrangement):
    _shows_its_descriptors(text)
    _round_trip(text)


# --- V121 exactly where no arrangement exists -------------------------------------------


def _small_files(n: int, seed: int) -> list[tuple[str, dict, int, bool]]:
    rng = random.Random(seed)
    out = []
    while len(out) < n:
        approach = rng.random() < 0.5
        motions = {t: k for t, hi in ((R, 3), (GH, 2), (GV, 3), (T, 2), (S, 1))
                   if (k := rng.randint(0, hi) if rng.random() < 0.5 else 0)}
        n_pauses = rng.randint(0, 6)
        if not (motions or n_pauses or approach):
            continue
        text = _file(motions, n_pauses, approach, rng.choice([None, *STATES]), rng)
        out.append((text, motions, n_pauses, approach))
    return out


#: Files the layout once refused although an arrangement shows them: a plane's gazes
#: laid out in another order than they were made (one then turned to where it stood).
ONCE_REFUSED = [
    ("behaviour t : curious\nstart 0.34m\nstandoff 12cm\napproach a=0.1\npause 0.5s x3\n"
     "retreat 20mm x2\ngaze vertical 10deg x3\n", {R: 2, GV: 3}, 3, True),
    ("behaviour t : confident\nstart 0.34m\nstandoff 12cm\npause 0.5s x4\nretreat 20mm x3\n"
     "gaze vertical 10deg x3\nshiver 3deg f=2.5Hz for 1.5s x3\n", {R: 3, GV: 3, S: 3}, 4,
     False),
]


def _v121_iff_none(text, motions, n_pauses, approach) -> None:
    result = _lint(text)
    v121 = [d for d in result.diagnostics if d.code == "V121"]
    exists = arrangement_exists(motions, n_pauses, approach)
    assert bool(v121) != exists, (text, [d.message for d in result.diagnostics])
    for d in v121:
        assert "no layout" not in d.message  # it names the need that stops it


@pytest.mark.parametrize(("text", "motions", "n_pauses", "approach"),
                         ONCE_REFUSED + _small_files(150, 12))
def test_v121_only_where_no_arrangement_exists(text, motions, n_pauses, approach):
    _v121_iff_none(text, motions, n_pauses, approach)


@pytest.mark.large
@pytest.mark.parametrize(("text", "motions", "n_pauses", "approach"),
                         _small_files(2000, 99))
def test_v121_only_where_no_arrangement_exists_large(text, motions, n_pauses, approach):
    _v121_iff_none(text, motions, n_pauses, approach)


# --- the example of a file refused with five pauses -------------------------------------

D015 = """behaviour d015 : confident
robot ur5
start 0.35m
standoff 15cm
retreat 10mm a=0.05 x1
pause 1.25s x5
gaze vertical 2deg x2
"""


def test_d015_without_an_approach_names_the_need_that_stops_it():
    """Without an approach the only motions are a retreat and two gazes: four places for
    pauses that do not touch. V121 says so, not that no layout exists."""
    assert not arrangement_exists({R: 1, GV: 2}, 5, False)
    (d,) = [d for d in _lint(D015).diagnostics if d.code == "V121"]
    assert "pause_count is declared 5" in d.message
    assert "no layout" not in d.message
    assert "pauses need motion between them" in d.message and "no approach" in d.message


def test_d015_with_its_approach_compiles_and_measures_five_pauses():
    """approach, gaze, pause, gaze, pause, retreat... shows all five."""
    text = D015.replace("retreat", "approach a=0.1\nretreat")
    assert arrangement_exists({R: 1, GV: 2}, 5, True)
    res = api.compile(source=text, path="d015.aou", check=False)
    assert res.ok, [d.message for d in res.diagnostics]
    assert res.measured.descriptors["pause_count"] == 5
    assert compare(res.document["descriptors"]["declared"], res.measured.descriptors) == []
