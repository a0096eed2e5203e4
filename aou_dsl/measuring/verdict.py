"""A recording (or a trajectory) judged against the behaviour it should show: each
descriptor declared by the ``.aou`` file beside the one measured, with its tolerance and
a pass or a fail, and the C-V point of each (``aouc measure REC --against FILE.aou``).

The declared values are the file's own (:func:`aou_dsl.lang.declared.declared`, the same
the compiler checks its output against), the tolerances those of the descriptor table
(:data:`aou_dsl.lang.descriptors.REGISTRY`), so a recording passes exactly when the
compiled trajectory would.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..core.codes import R408
from ..core.diagnostics import AouError, Diagnostic, Severity, Span, diag
from ..core.trajectory import Trajectory
from ..lang.cv import CVPoint
from ..lang.declared import declared, source_of
from ..lang.descriptors import REGISTRY
from ..lang.linter import FileResult, lint_file
from .measured import Measured, measure

__all__ = ["Row", "Verdict", "judge"]


@dataclass(frozen=True)
class Row:
    """One descriptor: ``declared`` and ``measured`` in its unit (None: absent; a count
    absent is 0), the ``tolerance`` a measured value may be off by (None where the
    descriptor is declared absent: it must be measured absent), ``ok`` whether it is
    within, and ``span`` the statement that declares it."""

    name: str
    unit: str
    declared: float | int | None
    measured: float | int | None
    tolerance: float | None
    ok: bool
    span: Span

    def to_json(self) -> dict:
        return {"descriptor": self.name, "unit": self.unit, "declared": _round(self.declared),
                "measured": _round(self.measured), "tolerance": _round(self.tolerance),
                "ok": self.ok}


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

    @property
    def ok(self) -> bool:
        """Whether every descriptor is within its tolerance."""
        return all(r.ok for r in self.rows)

    @property
    def failed(self) -> tuple[Row, ...]:
        return tuple(r for r in self.rows if not r.ok)

    def outside(self) -> list[Diagnostic]:
        """R408 for each descriptor outside its tolerance, at the statement declaring it."""
        out = []
        for r in self.failed:
            tol = "" if r.tolerance is None else f" (tolerance +-{_text(r.tolerance)})"
            out.append(diag(R408, f"{r.name}: declared {_text(r.declared, r.unit)}, "
                            f"measured {_text(r.measured, r.unit)} on `{self.path}`{tol}",
                            r.span, descriptor=r.name, declared=r.declared,
                            measured=r.measured, tolerance=r.tolerance))
        return out

    def to_json(self) -> dict:
        return {"path": self.path, "against": self.against, "robot": self.robot,
                "ok": self.ok, "descriptors": [r.to_json() for r in self.rows],
                "cv": {"declared": self.declared_cv.to_json(),
                       "measured": self.measured_cv.to_json()},
                "goal_from_behaviour": self.goal_from_file}


def _text(v: float | int | None, unit: str = "") -> str:
    if v is None:
        return "absent"
    return f"{v:.4g}{' ' + unit if unit else ''}"


def _round(v: float | int | None) -> float | int | None:
    return round(v, 6) if isinstance(v, float) else v


def _rows(lint: FileResult, measured: Measured) -> tuple[Row, ...]:
    b, tl = lint.behaviour, lint.timeline
    assert b is not None and tl is not None
    want = declared(b, tl)
    got = measured.descriptors
    rows = []
    for name, d in REGISTRY.items():
        w, g = want.get(name), got.get(name)
        if d.is_count:
            w, g = w or 0, g or 0
        tol = None if w is None else d.tolerance(float(w))
        p = source_of(b, name)
        rows.append(Row(name, d.unit, w, g, tol, d.matches(w, g),
                        p.span if p is not None else _absent_at(b)))
    return tuple(rows)


def _absent_at(b) -> Span:
    """Where a descriptor the file declares absent (no statement sets it) is said: its
    header, else its first statement; the whole file only when it has neither."""
    return b.header_span or (b.primitives[0].span if b.primitives else b.span)


def judge(rec: Trajectory, behaviour: str | FileResult) -> Verdict:
    """``rec`` measured and compared with the behaviour file ``behaviour`` (a path, or
    its lint). A recording without a goal is measured at the behaviour's goal (its
    ``goal`` line, else its robot's default).

    Raises:
        AouError: the file's errors when it does not lint; what measuring raises.
    """
    lint = lint_file(behaviour) if isinstance(behaviour, str) else behaviour
    if not lint.ok or lint.behaviour is None or lint.timeline is None or lint.cv is None:
        raise AouError([d for d in lint.diagnostics if d.severity is Severity.ERROR]
                       or lint.diagnostics)
    from_file = rec.goal is None
    if from_file:
        from ..robot.load import load_robot

        b = lint.behaviour
        goal = b.settings.goal or load_robot(rec.robot, rec.package_dirs).spec.goal
        rec = rec.with_(goal=tuple(float(x) for x in goal))
    m = measure(rec)
    return Verdict(rec.path, lint.path, rec.robot, _rows(lint, m), lint.cv, m.cv, m,
                   from_file, list(m.diagnostics))
