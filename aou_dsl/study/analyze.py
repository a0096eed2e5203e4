"""The analysis of a study's answers: the paper's statistics and more, as a report.

Participants are excluded first, each with the reason kept in the report: a repeated
participant id (the first submission counts), an incomplete one (a question of Part A
or Part B unanswered, or no end), a failed attention check. Then, per Part A expression
and per Part B pair, :mod:`.stats` tests the counts; Holm's correction runs across every
goodness-of-fit test of the report (the family); Part A's expressions are tested for
independence of the states chosen, and set against the states the files declare.
"""

from __future__ import annotations

import re
from collections import Counter, defaultdict
from statistics import mean, median, pstdev

from .answers import Row
from .spec import PART_B_OPTIONS, Study
from .stats import (
    DOMINANT,
    Fit,
    dominant,
    goodness_of_fit,
    holm,
    independence,
    participants_needed,
    wilson,
)

__all__ = ["VERDICTS", "analyze"]

#: Part B's verdicts in the paper's words, by the dominant answer.
VERDICTS = {"high": "the high variant", "low": "the low variant", "both": "both equally",
            "neither": "neither", None: "no dominant answer"}
#: Words left out of the free texts' top words.
STOP = frozenset("a an and the it is its it's to of in on at as be was were very robot "
                 "arm seems seemed like looks looked looking moves moving moved bit quite "
                 "that this with but or not for more".split())
TOP_WORDS = 5


def _participants(rows: list[Row], study: Study) -> tuple[dict[str, list[Row]], list[dict]]:
    """Each kept participant's rows, and the excluded ones with their reasons."""
    by: dict[str, list[Row]] = defaultdict(list)
    first_file: dict[str, str] = {}
    excluded: list[dict] = []
    dropped: set[str] = set()
    for r in rows:
        file = r.source.split("#")[0]
        again = first_file.setdefault(r.participant, file) != file or (
            r.part in ("A", "B") and any(q.part == r.part and q.item == r.item
                                         for q in by[r.participant]))
        if again:  # the first answers count; the report says the id answered again
            if r.participant not in dropped:
                dropped.add(r.participant)
                excluded.append({"participant": r.participant, "reason": "duplicate",
                                 "detail": "answered again (a second file or a question "
                                 "answered twice): the later answers are left out"})
            continue
        by[r.participant].append(r)
    kept: dict[str, list[Row]] = {}
    need_a = {s.id for s in study.part_a}
    need_b = {p.id for p in study.pairs}
    for pid, rs in by.items():
        done_a = {r.item for r in rs if r.part == "A"}
        done_b = {r.item for r in rs if r.part == "B"}
        failed = [r.item for r in rs if r.part == "attention" and r.passed is False]
        missing = sorted((need_a - done_a) | (need_b - done_b))
        if missing or not any(r.part == "end" for r in rs):
            excluded.append({"participant": pid, "reason": "incomplete",
                             "detail": "unanswered: " + (", ".join(missing) or "the end")})
        elif failed:
            excluded.append({"participant": pid, "reason": "attention",
                             "detail": "failed attention check " + ", ".join(failed)})
        else:
            kept[pid] = rs
    return kept, excluded


def _fit_json(fit: Fit, options: tuple[str, ...], holm_p: float | None) -> dict:
    n = fit.n
    return {
        "n": n, "chi2": fit.chi2, "df": fit.df, "p": fit.p, "p_holm": holm_p,
        "exact_p": fit.exact_p, "exact_method": fit.exact_method, "cohen_w": fit.cohen_w,
        "expected": fit.expected,
        "options": {o: {"count": c, "share": c / n, "ci95": list(wilson(c, n)),
                        "residual": r, "adjusted_residual": a}
                    for o, c, r, a in zip(options, fit.counts, fit.residuals, fit.adjusted,
                                          strict=True)},
    }


def _words(texts: list[str]) -> list[list]:
    words = Counter(w for t in texts for w in re.findall(r"[a-z]+(?:'[a-z]+)?", t.lower())
                    if w not in STOP and len(w) > 2)
    return [[w, c] for w, c in sorted(words.items(), key=lambda x: (-x[1], x[0]))[:TOP_WORDS]]


def analyze(rows: list[Row], study: Study) -> dict:
    """Every statistic of the report, as plain data (``results.json``)."""
    kept, excluded = _participants(rows, study)
    answers = [r for rs in kept.values() for r in rs]
    part_a, fits = [], []
    for s in study.part_a:
        mine = [r for r in answers if r.part == "A" and r.item == s.id]
        counts = [sum(r.state == o for r in mine) for o in study.options]
        fits.append(goodness_of_fit(counts, seed=study.seed) if mine else None)
        part_a.append((s, mine))
    part_b = []
    for p in study.pairs:
        mine = [r for r in answers if r.part == "B" and r.item == p.id]
        counts = [sum(r.answer == o for r in mine) for o in PART_B_OPTIONS]
        fits.append(goodness_of_fit(counts, seed=study.seed) if mine else None)
        part_b.append(p)
    adjusted = iter(holm([f.p_used for f in fits if f is not None]))
    holm_p = [next(adjusted) if f is not None else None for f in fits]
    out_a = []
    for (s, mine), fit, hp in zip(part_a, fits, holm_p, strict=False):
        entry: dict = {"id": s.id, "behaviour": s.path, "declared": s.state}
        if fit is not None:
            top = dominant(fit)
            ks = [r.intensity for r in mine if r.intensity is not None]
            entry.update(_fit_json(fit, study.options, hp),
                         dominant=None if top is None else study.options[top],
                         intensity={"n": len(ks), "mean": mean(ks), "median": median(ks),
                                    "sd": pstdev(ks)} if ks else None,
                         words=_words([r.description for r in mine]),
                         other_words=_words([r.other_text for r in mine]))
        out_a.append(entry)
    out_b = []
    for p, fit, hp in zip(part_b, fits[len(part_a):], holm_p[len(part_a):],
                                   strict=True):
        entry = {"id": p.id, "behaviour": p.path, "state": p.state,
                 "descriptor": p.descriptor, "low": p.low, "high": p.high}
        if fit is not None:
            top = dominant(fit)
            entry.update(_fit_json(fit, PART_B_OPTIONS, hp),
                         dominant=None if top is None else PART_B_OPTIONS[top],
                         verdict=VERDICTS[None if top is None else PART_B_OPTIONS[top]])
        out_b.append(entry)
    table = [[e["options"][o]["count"] for o in study.options] for e in out_a if "n" in e]
    indep = independence(table) if len(table) > 1 else None
    declared = sorted({s.state for s in study.part_a if s.state})
    confusion = {d: {o: sum(e["options"][o]["count"] for e in out_a
                            if e["declared"] == d and "n" in e) for o in study.options}
                 for d in declared}
    return {
        "format": "aou-study-results/1",
        "study": study.title,
        "participants": {"answered": len(kept) + len(excluded), "kept": len(kept),
                         "excluded": excluded},
        "threshold": DOMINANT,
        "part_a": out_a,
        "independence": None if indep is None else {
            "chi2": indep.chi2, "df": indep.df, "p": indep.p, "cramer_v": indep.cramer_v},
        "confusion": confusion,
        "part_b": out_b,
        "power": {f"w={w}": {"part_a": participants_needed(w, len(study.options)),
                             "part_b": participants_needed(w, len(PART_B_OPTIONS))}
                  for w in (0.3, 0.5)},
    }
