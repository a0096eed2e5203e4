"""Fitting a reach: where the arm cannot follow a pose of the motion (C301: outside its
workspace; C302: a joint at its limit; C303: a singularity), the statement whose gaze
angle, retreat or approach distance or tilt angle takes the hand there is brought back
within reach, by the least that keeps the order of values.

The rule, for the statement a refusal points at (the one whose episode IK failed):

- Only its positional value changes (`gaze horizontal 60deg` -> `gaze horizontal
  46.1deg`): the angle or distance that takes the hand where the arm cannot follow.
- Its **bound** ``R``, the largest magnitude at which IK follows every pose up to the
  statement's last episode (everything else as written), is found by bisection on a
  fixed grid (0 to :data:`SPAN` of the quantity, halved :data:`STEPS` times), so two
  files that differ only in that value find the same bound.
- The declared magnitude is compressed under ``R`` by the same increasing map as an
  acceleration (:func:`~aou_dsl.fit.plan.compress`), so two files that differ
  only in that value are fitted to values in the same order (a Part B variant pair keeps
  its contrast); the sign (a direction in a sequence) stays.
- When a later statement then fails, it is fitted the same way, and so on: the changes
  are every change the whole motion needs, said at once (the hint of the refusal
  without ``--fit``, the changes made with it).

Reaching is checked by the compiler's own IK from the start pose, episode by episode,
as the compiler follows the path; a fit whose file no longer expresses the declared
state is not offered.
"""

from __future__ import annotations

import math
from typing import Any

from ..core.codes import C301, C302, C303
from ..core.diagnostics import Diagnostic, Severity, Span, refused
from ..core.memo import cached
from ..lang.descriptors import REGISTRY
from ..lang.linter import FileResult, lint_source
from ..lang.primitives import APPROACH, GAZE, KINDS, RETREAT, TILT
from .quantity import UNITS, first
from .refusals import Unreachable, answered, first_error
from .rounding import written
from .text_edits import splice, statement

__all__ = ["REACH", "STEPS", "Statement", "offered", "with_reach_fit"]

#: The refusals a reach fit answers.
REACH = (C301, C302, C303)
#: Bisection steps of a bound (on a grid of SPAN / 2**STEPS).
STEPS = 14
#: The range searched for a bound, in SI units, by the unit's dimension.
SPAN = {"angle": math.pi, "length": 2.0}
#: Statements more than this are not fitted in one refusal.
MOST = 4

_LIMIT = {C301: "reach", C302: "position", C303: "singularity"}


#: The units of the descriptors a positional value that moves the hand sets.
_PLACE_UNITS = ("m", "deg")


def _descriptor(words: list[str]) -> str | None:
    """The descriptor a statement's positional value sets (None: none): the one of its
    kind, in a unit of length or angle, that no ``key=`` argument sets; of several (a
    gaze's planes), the one whose episode value the next word names."""
    kind = KINDS.get(words[0]) if words else None
    if kind is None:
        return None
    found = [d for d in REGISTRY.values() if d.kind == kind.name and not d.is_count
             and d.unit in _PLACE_UNITS and d.ir_field not in kind.keys]
    if len(found) > 1:
        found = [d for d in found if d.key in words[1:2]]
    return found[0].name if len(found) == 1 else None


class Statement:
    """One statement's positional value, and the file's text with another value there."""

    def __init__(self, text: str, line: int, col: int, end_col: int,
                 kinds: tuple[str, ...] = (GAZE, RETREAT, TILT, APPROACH)) -> None:
        self.text, self.line, self.col = text, line, col
        self.stmt, self.stop = statement(text, line, col, end_col)
        self.match = first(self.stmt)
        words = self.stmt.split()
        self.ok = bool(words) and words[0] in kinds \
            and self.match is not None
        if self.ok:
            assert self.match is not None
            self.written, self.unit = self.match["number"], self.match["unit"]
            self.dim, self.scale = UNITS[self.unit]
            self.value = float(self.written) * self.scale  # SI, signed
            self.descriptor = _descriptor(words)

    def record(self, fitted: str, stmt: str, bound: float, joint: str | None,
               limit: str | None) -> dict[str, Any]:
        """The change of this value to ``fitted`` (as written; ``stmt`` the statement
        then), under ``bound`` (SI), as a refusal's field ``reach`` holds it."""
        return {"line": self.line, "col": self.col, "end_col": self.stop + 1,
                "key": self.dim, "declared": self.written, "fitted": fitted,
                "unit": self.unit, "bound": bound / self.scale, "joint": joint,
                "limit": limit, "descriptor": self.descriptor, "statement": stmt}

    def with_value(self, si: float) -> tuple[str, str]:
        """The statement and the file's text with the magnitude ``si`` (SI) written in
        the statement's unit, rounded down to 4 significant digits."""
        assert self.match is not None
        shown = written(si / self.scale, 4)
        if self.value < 0:
            shown = "-" + shown
        a, b = self.match.span("number")
        stmt = self.stmt[:a] + shown + self.stmt[b:]
        return stmt, splice(self.text, self.line, self.col, self.stop, stmt)


def _reach(lint: FileResult, robot: str, package_dirs: tuple[str, ...]) -> Any:
    """``reaches(timeline) -> (episode index, IKFailure) | None``: where IK first fails
    to follow the motion (index -1: the start pose), for the behaviour's arm and goal."""
    import numpy as np

    from ..compiler.pipeline import MIN_WAYPOINTS, STEP_ANGLE, STEP_LENGTH
    from ..lang.primitives import KINDS, Timing
    from ..robot.geometry import reach_frame
    from ..robot.ik import solve_path
    from ..robot.load import load_arm

    b = lint.behaviour
    assert b is not None
    arm = load_arm(robot, None, package_dirs)
    frame = reach_frame(b.settings.goal or arm.spec.goal,
                        b.settings.start_direction or arm.spec.start_direction)

    def targets(ep) -> list:
        step = STEP_LENGTH if KINDS[ep.kind].translation else STEP_ANGLE
        n = max(MIN_WAYPOINTS, math.ceil(ep.path_length / step) + 1)
        return [frame.target(ep.start.lerp(ep.end, f)) for f in np.linspace(0.0, 1.0, n)]

    def reaches(tl) -> tuple[int, Any] | None:
        if not tl.episodes:
            return None
        ik = solve_path(arm, [frame.target(tl.episodes[0].start)])
        if ik.failure is not None:
            return -1, ik.failure
        q = ik.q[0]
        for i, ep in enumerate(tl.episodes):
            if KINDS[ep.kind].timing in (Timing.HOLD, Timing.OSCILLATION):
                continue
            ik = solve_path(arm, targets(ep), q)
            if ik.failure is not None:
                return i, ik.failure
            q = ik.q[-1]
        return None

    return reaches


def _bound(st: Statement, path: str, last: int, follows: Any) -> float:
    """The largest magnitude (SI) on the fixed grid at which IK follows the motion past
    episode ``last`` (0.0: none found). Grid points at or above the declared value are
    taken as failing (it failed), so they cost nothing."""
    lo, hi = 0.0, SPAN[st.dim]
    for _ in range(STEPS):
        mid = (lo + hi) / 2.0
        if mid < abs(st.value) and follows(st.with_value(mid)[1], path, last):
            lo = mid
        else:
            hi = mid
    return lo


def _candidate(text: str, path: str, episodes: Any, last: int, follows: Any
               ) -> tuple[Statement, float] | str:
    """The statement to change and its bound: the refused one (the last of
    ``episodes``) when some value of it is followed, else the nearest earlier one whose
    angle or distance takes the hand to where the refused one starts."""
    seen: list[tuple[int, int]] = []
    for ep in reversed(episodes):
        at = (ep.span.line, ep.span.col)
        if at in seen:
            continue
        seen.append(at)
        st = Statement(text, ep.span.line, ep.span.col, ep.span.end_col)
        if st.ok:
            bound = _bound(st, path, last, follows)
            if bound > 0.0:
                return st, bound
    refused = Statement(text, *seen[0], episodes[-1].span.end_col) if seen else None
    return f"no angle or distance of `{refused.stmt if refused else '?'}` or of a " \
        "statement before it is followed by the arm"


def _fits(lint: FileResult, d: Diagnostic, robot: str, package_dirs: tuple[str, ...]
          ) -> list[dict[str, Any]] | str:
    """Every change the motion needs to be followed, as records (see the module), or
    why none is offered."""
    from .plan import compress

    reaches = _reach(lint, robot, package_dirs)

    def follows(text: str, path: str, last: int) -> bool:
        again = lint_source(text, path)
        if not again.ok or again.timeline is None:
            return False
        failed = reaches(again.timeline)
        return failed is None or failed[0] > last

    text, path = lint.source or "", lint.path
    changes: list[dict[str, Any]] = []
    first: dict[tuple[int, int], tuple[str, float, int]] = {}
    span, code, failure = d.span, d.code, d.refusal.joint
    for _ in range(MOST):
        tl = lint_source(text, path).timeline
        last = -1 if tl is None else max((i for i, e in enumerate(tl.episodes) if (
            e.span.line, e.span.col) == (span.line, span.col)), default=-1)
        if tl is None or last < 0:
            return "the refused statement makes no episode of the motion"
        found = _candidate(text, path, tl.episodes[:last + 1], last, follows)
        if isinstance(found, str):
            return found
        st, bound = found
        # a statement changed before is fitted again from its declared value
        was = first.setdefault((st.line, st.col), (st.written, abs(st.value), st.stop + 1))
        stmt, new_text = st.with_value(compress(was[1], bound))
        refused = lint_source(new_text, path)
        if not refused.ok:
            return f"`{stmt}`, the least change under the arm's bound " \
                f"({bound / st.scale:.4g}{st.unit}), is a value the language does not " \
                f"take: {first_error(refused.diagnostics)}"
        if not follows(new_text, path, last):
            return f"`{stmt}` is not followed either"
        changes = [c for c in changes if (c["line"], c["col"]) != (st.line, st.col)]
        fitted = Statement(new_text, st.line, st.col, st.col + len(stmt)).written
        changes.append(st.record(fitted, stmt, bound, failure, _LIMIT.get(code, "reach"))
                       | {"end_col": int(was[2]), "declared": was[0]})
        text = new_text
        again = lint_source(text, path)
        failed = reaches(again.timeline) if again.timeline is not None else (-1, None)
        if failed is None:
            state = lint.behaviour.state if lint.behaviour is not None else None
            if state is not None and (again.cv is None or again.cv.state != state):
                found = again.cv.state.value if again.cv is not None else "nothing"
                return f"the fitted file would express `{found}`, not `{state.value}`"
            return changes
        index, fail = failed
        if index < 0 or again.timeline is None or fail is None:
            return "the start pose is then out of reach"
        span, failure = again.timeline.episodes[index].span, fail.joint
        code = {"UNREACHABLE": C301, "JOINT_LIMIT": C302}.get(fail.status.name, C303)
    return f"more than {MOST} statements would change"


@cached(maxsize=32)
def _remembered(source: str, path: str, robot: str, package_dirs: tuple[str, ...],
                code: str, span: Span, joint: str | None, key: tuple
                ) -> list[dict[str, Any]] | str:
    """:func:`_fits`, kept for the last texts and robot files (``key``: their
    content): an editor builds the same text again (a refusal's search costs about a
    second)."""
    lint = lint_source(source, path)
    if lint.behaviour is None or lint.timeline is None:
        return "the file does not lint"
    return _fits(lint, refused(code, "", span, Unreachable("", 0.0, joint)), robot,
                 package_dirs)


def with_reach_fit(res: Any, robot: str | None, package_dirs: tuple[str, ...]) -> Any:
    """``res`` (a build result) with each reach refusal at a statement given the changes
    that bring the whole motion within reach: as the hint (``write `gaze horizontal
    46.1deg` at line 5``) and as the field ``reach`` (read by ``--fit``)."""
    lint = res.lint
    b = lint.behaviour
    if b is None or lint.source is None:
        return res
    out = []
    for d in res.diagnostics:
        if not isinstance(d.refusal, Unreachable) or d.severity is not Severity.ERROR \
                or not d.refusal.time or d.span.path != lint.path or d.span.line < 1:
            out.append(d)
            continue
        from ..robot.load import robot_key

        arm = robot or b.settings.robot
        found = _remembered(lint.source, lint.path, arm, package_dirs, d.code, d.span,
                            d.refusal.joint, robot_key(arm, package_dirs))
        found = found if isinstance(found, str) else [dict(c) for c in found]
        if isinstance(found, str):
            why = f"no smaller angle or distance is offered: {found}"
            out.append(answered(d, f"{d.hint}; {why}" if d.hint else why,
                                not_offered=found))
            continue
        out.append(offered(d, found))
    res.diagnostics = out
    return res


def offered(d: Diagnostic, records: list[dict[str, Any]]) -> Diagnostic:
    """``d`` with the changes ``records`` (a reach's, a shiver amplitude's) as its hint
    (``write `gaze horizontal 46.1deg` at line 5``, before what it said) and its field
    ``reach`` (read by ``--fit``)."""
    said = "; ".join(f"`{c['statement']}` at line {c['line']}" for c in records)
    hint = f"write {said}" + (f"; or {d.hint}" if d.hint else "")
    return answered(d, hint, offered=records)
