"""A recording (or a trajectory) judged against the behaviour it should show: each
descriptor declared by the ``.aou`` file beside the one measured, with its tolerance and
a pass, a fail or an inconclusive (the measured value's interval straddles the
tolerance's edge), and the C-V point of each (``aouc measure REC --against FILE.aou``).
The plugins' descriptors follow the eleven, judged the same way; a file that uses a
plugin kind no ``measure`` part recognises is not judged (K802, :mod:`.recognisers`).

The declared values are the file's own (:func:`aou_dsl.lang.declared.declared`, the same
the compiler checks its output against), the tolerances those of the descriptor table
(:data:`aou_dsl.lang.descriptors.REGISTRY`), so a recording passes exactly when the
compiled trajectory would.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from ..core.codes import R408, R412, R413
from ..core.diagnostics import AouError, Diagnostic, Severity, Span, diag
from ..core.trajectory import Trajectory
from ..lang.cv import CVPoint
from ..lang.declared import declared, source_of
from ..lang.descriptors import REGISTRY, Descriptor
from ..lang.layout import episode_values
from ..lang.linter import FileResult, lint_file
from ..lang.primitives import KINDS
from .measured import Measured, measure
from .recognisers import extra_descriptors, extra_values, missing_part

__all__ = ["FAIL", "INCONCLUSIVE", "PASS", "Row", "Verdict", "judge"]


PASS, FAIL, INCONCLUSIVE = "pass", "fail", "inconclusive"


@dataclass(frozen=True)
class Row:
    """One descriptor: ``declared`` and ``measured`` in its unit (None: absent; a count
    absent is 0), the ``tolerance`` a measured value may be off by (None where the
    descriptor is declared absent: it must be measured absent), ``ok`` whether it
    passes, and ``span`` the statement that declares it. ``low`` and ``high`` are the
    measured value's 95 % interval (a noisy recording's; the value itself for a
    trajectory without noise), ``result`` pass, fail or inconclusive: inconclusive
    when the interval straddles the tolerance's edge (or the noise can flip a count or
    a presence), so that the noise alone could make it pass or fail."""

    name: str
    unit: str
    declared: float | int | None
    measured: float | int | None
    tolerance: float | None
    ok: bool
    span: Span
    low: float | int | None = None
    high: float | int | None = None
    result: str = PASS

    def to_json(self) -> dict:
        return {"descriptor": self.name, "unit": self.unit, "declared": _round(self.declared),
                "measured": _round(self.measured), "tolerance": _round(self.tolerance),
                "ok": self.ok, "result": self.result, "low": _round(self.low),
                "high": _round(self.high)}


@dataclass(frozen=True)
class Verdict:
    """A recording judged against a behaviour file.

    Attributes:
        path: the recording; against: the ``.aou`` file.
        robot: the recording's robot.
        rows: one per descriptor, in the table's order.
        declared_cv: the C-V point of the file's primitives; measured_cv: of the motion.
        measured: the whole measurement (episodes, line of sight).
        goal_from_file: the recording had no goal and the behaviour's was used.
        diagnostics: what measuring said (R405 and the like).
    """

    path: str
    against: str
    robot: str
    rows: tuple[Row, ...]
    declared_cv: CVPoint
    measured_cv: CVPoint
    measured: Measured
    goal_from_file: bool = False
    diagnostics: list[Diagnostic] = field(default_factory=list)
    #: The kinds of motion the file's episodes make (what they do: an approach of
    #: negative length is a retreat), and where to say a kind it lacks.
    kinds: frozenset[str] = frozenset()
    header: Span | None = None

    @property
    def ok(self) -> bool:
        """Whether every descriptor passes (within its tolerance, interval and all)."""
        return all(r.ok for r in self.rows)

    @property
    def failed(self) -> tuple[Row, ...]:
        return tuple(r for r in self.rows if r.result == FAIL)

    @property
    def inconclusive(self) -> tuple[Row, ...]:
        return tuple(r for r in self.rows if r.result == INCONCLUSIVE)

    @property
    def result(self) -> str:
        """fail when a descriptor fails, else inconclusive when one is, else pass."""
        return FAIL if self.failed else (INCONCLUSIVE if self.inconclusive else PASS)

    def undecided(self) -> list[Diagnostic]:
        """R412 for each descriptor whose interval straddles its tolerance's edge."""
        out = []
        for r in self.inconclusive:
            tol = "" if r.tolerance is None else f", tolerance +-{_text(r.tolerance)}"
            out.append(diag(R412, f"{r.name}: declared {_text(r.declared, r.unit)}, "
                            f"measured {_text(r.measured, r.unit)} on `{self.path}`, "
                            f"95 % interval {_text(r.low)} to {_text(r.high)}{tol}: the "
                            "recording's noise leaves it undecided",
                            r.span, descriptor=r.name, declared=r.declared,
                            measured=r.measured, tolerance=r.tolerance, low=r.low,
                            high=r.high))
        return out

    def outside(self) -> list[Diagnostic]:
        """R408 for each descriptor outside its tolerance, at the statement declaring it."""
        out = []
        for r in self.failed:
            tol = "" if r.tolerance is None else f" (tolerance +-{_text(r.tolerance)})"
            noisy = isinstance(r.measured, float) and r.low is not None and \
                r.high is not None and r.low < r.high  # a count's copies all read it
            within = f", 95 % interval {_text(r.low)} to {_text(r.high)}" if noisy else ""
            out.append(diag(R408, f"{r.name}: declared {_text(r.declared, r.unit)}, "
                            f"measured {_text(r.measured, r.unit)} on `{self.path}`"
                            f"{within}{tol}", r.span, descriptor=r.name,
                            declared=r.declared, measured=r.measured, tolerance=r.tolerance,
                            low=r.low, high=r.high))
        return out

    def undeclared(self) -> list[Diagnostic]:
        """R413 for each kind of motion the recording's episodes read as that the file
        does not declare, each episode read by its kind's invariant
        (:meth:`~aou_dsl.lang.primitives.Kind.reads_as`: a shiver slower than a tremor
        reads as slow rolls, a tilt), with the times of those episodes."""
        seen: dict[str, list[tuple[str, float, float]]] = {}
        for e in self.measured.episodes:
            if e.kind not in KINDS:
                continue
            reads = KINDS[e.kind].reads_as(e.values, e.t_end - e.t_start)
            if reads not in self.kinds:
                seen.setdefault(reads, []).append((e.kind, e.t_start, e.t_end))
        out = []
        for kind, eps in seen.items():
            when = ", ".join(f"{a:.2f}-{b:.2f} s" + (
                "" if k == kind else f" (measured as a {k}, {_why(k, self.measured, a)})")
                for k, a, b in eps[:4]) + (f" and {len(eps) - 4} more" if len(eps) > 4 else "")
            out.append(diag(R413, f"the motion on `{self.path}` reads as a {kind} at "
                            f"{when}; the file declares no {kind}", self.header or
                            Span(self.against, 1, 1, 1, 1), hint=f"a {kind} looks like "
                            f"this: {KINDS[kind].look}", kind=kind,
                            episodes=[[k, round(a, 4), round(b, 4)] for k, a, b in eps]))
        return out

    def to_json(self) -> dict:
        return {"path": self.path, "against": self.against, "robot": self.robot,
                "ok": self.ok, "result": self.result,
                "descriptors": [r.to_json() for r in self.rows],
                "cv": {"declared": self.declared_cv.to_json(),
                       "measured": self.measured_cv.to_json()},
                "goal_from_behaviour": self.goal_from_file}


def _text(v: float | int | None, unit: str = "") -> str:
    if v is None:
        return "absent"
    return f"{v:.4g}{' ' + unit if unit else ''}"


def _why(kind: str, m: Measured, t0: float) -> str:
    """Why an episode measured as ``kind`` reads as another: its invariant's number."""
    e = next(x for x in m.episodes if x.kind == kind and x.t_start == t0)
    f = e.values.get("frequency")
    return f"{f:.2g} Hz, slower than a tremor" if f is not None else "by its look"


def _round(v: float | int | None) -> float | int | None:
    return round(v, 6) if isinstance(v, float) else v


def _extra_declared(b, tl) -> dict[str, float | int | None]:
    """The plugins' descriptors the file declares: written (descriptor form: its
    statement's count or value, as the eleven are read) or derived from its timeline."""
    extra = extra_descriptors()
    if b.form != "descriptor":
        return extra_values(episode_values(tl.episodes))
    out: dict[str, float | int | None] = {}
    for d in extra:
        node = b.first(d.kind)
        if node is None or node.count == 0:
            out[d.name] = 0 if d.is_count else None
        else:
            out[d.name] = node.count if d.is_count else KINDS[d.kind].values(node)[d.key]
    return out


def _rows(lint: FileResult, measured: Measured) -> tuple[Row, ...]:
    b, tl = lint.behaviour, lint.timeline
    assert b is not None and tl is not None
    want: Mapping[str, float | int | None] = declared(b, tl)
    got: Mapping[str, float | int | None] = measured.descriptors
    extra = extra_descriptors()
    if extra:  # the plugins' after the eleven, unless the declared side has them already
        mine = _extra_declared(b, tl)
        want = {**want, **{d.name: want[d.name] if d.name in want else mine.get(d.name)
                           for d in extra}}
        got = {**got, **measured.extra}
    rows = []
    for d in (*REGISTRY.values(), *extra):
        name = d.name
        w, g = want.get(name), got.get(name)
        if d.is_count:
            w, g = w or 0, g or 0
        tol = None if w is None else d.tolerance(float(w))
        p = source_of(b, name) if name in REGISTRY else b.first(d.kind)
        spread = measured.uncertainty.get(name)
        lo, hi, stable = (g, g, True) if spread is None else (
            spread.low, spread.high, spread.stable)
        if d.is_count:
            lo, hi = lo or 0, hi or 0
        result = _result(d, w, g, lo, hi, stable)
        rows.append(Row(name, d.unit, w, g, tol, result == PASS,
                        p.span if p is not None else _absent_at(b), lo, hi, result))
    return tuple(rows)


def _result(d: Descriptor, want: float | int | None, got: float | int | None,
            low: float | int | None, high: float | int | None, stable: bool) -> str:
    """pass when the whole interval ``low..high`` of the measured ``got`` matches the
    declared ``want``, fail when none of it does, else inconclusive. A presence the
    noise can flip (``stable`` False), and a value not to be trusted (R411), are
    inconclusive: the recording cannot tell, and an interval a wrong clock or a wrong
    segmentation moved can miss the tolerance as a whole. A count the noise can flip
    fails when no copy reads the declared count."""
    if want is None or got is None:
        if stable:
            return PASS if d.matches(want, got) else FAIL
        return INCONCLUSIVE
    if low is None or high is None:
        return PASS if d.matches(want, got) else FAIL
    if not stable and not d.is_count:
        return INCONCLUSIVE
    tol = d.tolerance(float(want))
    if d.matches(want, low) and d.matches(want, high) and stable:
        return PASS
    if float(high) < float(want) - tol - 1e-12 or float(low) > float(want) + tol + 1e-12:
        return FAIL
    return INCONCLUSIVE


def _absent_at(b) -> Span:
    """Where a descriptor the file declares absent (no statement sets it) is said: its
    header, else its first statement; the whole file only when it has neither."""
    return b.header_span or (b.primitives[0].span if b.primitives else b.span)


def judge(rec: Trajectory, behaviour: str | FileResult) -> Verdict:
    """``rec`` measured and compared with the behaviour file ``behaviour`` (a path, or
    its lint). A recording without a goal is measured at the behaviour's goal (its
    ``goal`` line, else its robot's default).

    Raises:
        AouError: the file's errors when it does not lint; K802 when it uses a plugin
            kind that no ``measure`` part recognises; what measuring raises.
    """
    lint = lint_file(behaviour) if isinstance(behaviour, str) else behaviour
    if not lint.ok or lint.behaviour is None or lint.timeline is None or lint.cv is None:
        raise AouError([d for d in lint.diagnostics if d.severity is Severity.ERROR]
                       or lint.diagnostics)
    unread = missing_part({e.kind for e in lint.timeline.episodes},
                          {e.kind: e.span for e in reversed(lint.timeline.episodes)})
    if unread:  # its episodes would be measured as other kinds: every verdict wrong
        raise AouError(unread)
    from_file = rec.goal is None
    if from_file:
        from ..robot.load import load_robot

        b = lint.behaviour
        goal = b.settings.goal or load_robot(rec.robot, rec.package_dirs).spec.goal
        rec = rec.with_(goal=tuple(float(x) for x in goal))
    m = measure(rec)
    b = lint.behaviour
    return Verdict(rec.path, lint.path, rec.robot, _rows(lint, m), lint.cv, m.cv, m,
                   from_file, list(m.diagnostics),
                   frozenset(e.kind for e in lint.timeline.episodes), _absent_at(b))
