"""Simulated participants: answers drawn from a declared policy, in the study's own format.

A policy gives, per question, the probability of each answer. Without one, each
participant chooses a Part A behaviour's declared state with probability
:data:`DEFAULT_AGREEMENT` (the rest spread evenly over the other options) and a Part B
pair's high variant with the same probability (the rest spread over low, both and
neither). A policy file (TOML) overrides any question:

    [part_a.A1]          # the blind id of the question, or `default`
    confident = 0.8
    curious = 0.2
    [part_b.default]
    high = 0.5
    both = 0.5

Each participant draws from a generator seeded by the study's seed and their number, so
a simulation is the same every run, and orders and sides are drawn as the built page
draws them (shuffled Part A and Part B orders, each pair's side).
"""

from __future__ import annotations

import math
import tomllib

import numpy as np

from ..core.codes import E704
from ..core.diagnostics import AouError, Span, diag
from ..core.inputs import read_input_text
from .spec import PART_B_OPTIONS, Study

__all__ = ["DEFAULT_AGREEMENT", "Policy", "read_policy", "simulate"]

#: The probability a default simulated participant gives the designed answer.
DEFAULT_AGREEMENT = 0.7

Policy = dict[str, dict[str, float]]  # question id (or "A:default"...) -> answer -> p


def _default(options: tuple[str, ...], favourite: str | None) -> dict[str, float]:
    if favourite not in options:
        return {o: 1 / len(options) for o in options}
    rest = (1 - DEFAULT_AGREEMENT) / (len(options) - 1)
    return {o: DEFAULT_AGREEMENT if o == favourite else rest for o in options}


def _checked(path: str, key: str, table, options: tuple[str, ...]) -> dict[str, float]:
    where = Span.whole_file(path)
    if not isinstance(table, dict) or not table:
        raise AouError(diag(E704, f"`{key}`: expected a table of answer = probability", where))
    for name, p in table.items():
        if name not in options:
            raise AouError(diag(E704, f"`{key}.{name}`: not an answer of that question "
                                f"({', '.join(options)})", where))
        if isinstance(p, bool) or not isinstance(p, int | float) or not 0 <= p <= 1 \
                or not math.isfinite(p):
            raise AouError(diag(E704, f"`{key}.{name}`: expected a probability in [0, 1]",
                                where))
    if abs(sum(table.values()) - 1) > 1e-6:
        raise AouError(diag(E704, f"`{key}`: the probabilities sum to "
                            f"{sum(table.values()):g}, not 1", where))
    return {o: float(table.get(o, 0.0)) for o in options}


def read_policy(path: str, study: Study) -> Policy:
    """A policy file, checked against the study (E704)."""
    text = read_input_text(path, "study")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise AouError(diag(E704, f"not TOML: {exc}", Span.whole_file(path))) from None
    policy: Policy = {}
    known = {"part_a": ({s.id for s in study.part_a}, study.options),
             "part_b": ({p.id for p in study.pairs}, PART_B_OPTIONS)}
    for part, tables in data.items():
        if part not in known or not isinstance(tables, dict):
            raise AouError(diag(E704, f"`{part}`: a policy has [part_a.ID] and "
                                "[part_b.ID] tables", Span.whole_file(path)))
        ids, options = known[part]
        for qid, table in tables.items():
            if qid != "default" and qid not in ids:
                raise AouError(diag(E704, f"`{part}.{qid}`: the study has no such question "
                                    f"({', '.join(sorted(ids))})", Span.whole_file(path)))
            policy[f"{part[-1].upper()}:{qid}"] = _checked(path, f"{part}.{qid}", table,
                                                           options)
    return policy


def _probs(policy: Policy, part: str, qid: str, options, favourite) -> np.ndarray:
    p = policy.get(f"{part}:{qid}") or policy.get(f"{part}:default") or \
        _default(options, favourite)
    return np.array([p[o] for o in options])


def simulate(study: Study, participants: int, policy: Policy | None = None) -> list[dict]:
    """The rows ``participants`` simulated participants would record, as the page
    records them (:mod:`.answers`)."""
    policy = policy or {}
    rows: list[dict] = []
    for k in range(1, participants + 1):
        pid = f"sim{k:05d}"
        rng = np.random.default_rng([study.seed, k])
        order = 0
        for i in rng.permutation(len(study.part_a)):
            s = study.part_a[int(i)]
            p = _probs(policy, "A", s.id, study.options, s.state)
            state = study.options[int(rng.choice(len(p), p=p))]
            order += 1
            rows.append({"participant": pid, "aou_part": "A", "aou_item": s.id,
                         "state": state, "other_text": "unsure" if state == "others" else "",
                         "description": f"it moves {state}",
                         "intensity": int(rng.integers(1, study.intensity + 1)),
                         "order": order})
        for i in rng.permutation(len(study.pairs)):
            pair = study.pairs[int(i)]
            p = _probs(policy, "B", pair.id, PART_B_OPTIONS, "high")
            rows.append({"participant": pid, "aou_part": "B", "aou_item": pair.id,
                         "answer": PART_B_OPTIONS[int(rng.choice(4, p=p))],
                         "left": "low" if rng.random() < 0.5 else "high",
                         "order": order + 1})
            order += 1
        rows.append({"participant": pid, "aou_part": "end", "aou_item": "", "order": order})
    return rows
