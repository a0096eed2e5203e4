"""What a descriptor-form file needs of its layout, read from the kinds' needs.

Every kind says what its episodes need around them to count (:class:`~.primitives.kind.
Needs`: a retreat a pause before and after it, a gaze a pause after it, pauses motion
between them). A layout *shows* a file when every descriptor the file writes can be read
back from it: no two pauses touch, every episode of a kind with a count counts, and each
value descriptor has an episode that counts. The layout tries arrangements until one
shows the file (:func:`shows_all`). Pure Python.
"""

from __future__ import annotations

from collections.abc import Sequence

from . import descriptors
from .descriptors import Descriptor, EpisodeValues, qualify
from .ir import Behaviour
from .primitives import APPROACH, KINDS, PAUSE
from .timeline import Episode

__all__ = ["episode_values", "episodes_of", "every_counts", "shows_all",
           "why_not"]


def every_counts(kind: str) -> bool:
    """Whether every episode of ``kind`` must count for its descriptors to show: a kind
    with a count (a retreat) or one no descriptor table knows (a plugin's, to be safe);
    not a kind whose descriptors are values one counting episode shows (a gaze's angle)."""
    mine = [d for d in descriptors.every_descriptor().values() if d.kind == kind]
    return not mine or any(d.is_count for d in mine)


def _sets(node, d: Descriptor) -> bool:
    """Whether statement ``node`` sets descriptor ``d`` (a gaze statement sets only its
    plane's)."""
    return node.kind == d.kind and getattr(node, "plane", d.key) in (d.key, None)


def episodes_of(b: Behaviour, kind: str) -> int:
    """How many episodes the file writes of ``kind``."""
    return sum(p.count for p in b.primitives if p.kind == kind)


def episode_values(episodes: Sequence[Episode]) -> list[EpisodeValues]:
    """A timeline's episodes as the descriptors see them, on the planned clock."""
    out, t = [], 0.0
    for e in episodes:
        out.append(EpisodeValues(e.kind, t, t + e.duration, KINDS[e.kind].episode_values(e)))
        t += e.duration
    return out


def shows_all(b: Behaviour, episodes: Sequence[Episode]) -> bool:
    """Whether a layout's ``episodes`` show every descriptor the file writes, as far as
    the episodes' places decide it (their values are the statements')."""
    eps = qualify(episode_values(episodes))
    if sum(1 for e in eps if e.kind == PAUSE) != episodes_of(b, PAUSE):
        return False
    for e in eps:
        if not e.counts and every_counts(e.kind):
            return False
    for d in descriptors.every_descriptor().values():
        if d.is_count or d.kind not in KINDS:
            continue
        want = any(p.count for p in b.primitives if _sets(p, d))
        got = any(e.counts and e.kind == d.kind and d.key in e.values for e in eps)
        if want != got:
            return False
    return True


def _a(word: str) -> str:
    return f"{'an' if word[:1] in 'aeiou' else 'a'} {word}"


def why_not(b: Behaviour) -> str | None:
    """The kinds' need that keeps every arrangement of ``b`` from showing what it
    writes, found by counting (bounds that hold for any arrangement); None when counting
    finds none (then only a search can tell)."""
    written = {k: episodes_of(b, k) for k in dict.fromkeys(p.kind for p in b.primitives)}
    for kind, n in written.items():
        needs = KINDS[kind].needs if kind in KINDS else None
        lacking = [k for k in needs.around if not written.get(k)] if n and needs else []
        if needs is not None and lacking:
            return f"{needs.words(kind, PAUSE)}, and this file has no {lacking[0]}"
    n_p = written.get(PAUSE, 0)
    moving = sum(n for k, n in written.items() if k not in (PAUSE, APPROACH))
    if n_p > moving + 1 and not written.get(APPROACH):
        return (f"pauses need motion between them, and with no approach this file's "
                f"{moving} other episode{'s' if moving != 1 else ''} leave room for "
                f"{moving + 1}")
    least, words = _least_pauses(b, written)
    if n_p < least:
        return f"{'; '.join(words)}: this file needs at least {least} pauses, and has {n_p}"
    return None


def _least_pauses(b: Behaviour, written: dict[str, int]) -> tuple[int, list[str]]:
    """The fewest pauses any arrangement needs, and the needs that ask for them: a pause
    ends at most one episode that needs one after it and starts at most one that needs
    one before it; the first of a run of episodes that need a pause on both sides starts
    at a pause nothing ends, unless another kind's episode ends there."""
    before = after = both = after_only = 0
    ends: set[tuple[str, str | None]] = set()
    words = []
    for kind, n in written.items():
        needs = KINDS[kind].needs if kind in KINDS else None
        if not n or needs is None or PAUSE not in needs.around:
            continue
        words.append(needs.words(kind, PAUSE) or "")
        pre, post = needs.preceded_by == PAUSE, needs.followed_by == PAUSE
        if post and not every_counts(kind):  # one episode per value it shows suffices
            ends.update((kind, getattr(p, "plane", None)) for p in b.primitives
                        if p.kind == kind and p.count)
            continue
        before += n if pre else 0
        after += n if post else 0
        both += n if pre and post else 0
        after_only += n if post and not pre else 0
    extra = 1 if both and not ends and not after_only else 0
    return max(before, after + len(ends) + extra), words
