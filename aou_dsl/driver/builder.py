"""``aouc compile`` as a library: one ``.aou`` file -> a checked, measured trajectory document.

The steps: lint (stop on errors), compile the timeline validation laid out, check the
trajectory in PyBullet (on a clock of at least :data:`CHECK_RATE`, whatever the output
rate), measure the result with :mod:`aou_dsl.measuring` (the declare -> compile -> measure
round trip, recorded in the output), and build the trajectory document. Writing is the
caller's, so a failed build leaves nothing behind.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

from ..core.codes import C301, C302, C303, C305, C306, C310, C311
from ..core.diagnostics import AouError, Diagnostic, Severity, Span, diag, has_errors
from ..core.options import BuildOptions, SceneOptions
from ..fit.refusals import AccelerationShort, Unreachable
from ..lang.linter import FileResult, lint_file, lint_source

if TYPE_CHECKING:  # the numerical stages load only when a build runs
    from ..compiler.pipeline import CompileResult
    from ..core.options import SceneOptions
    from ..core.trajectory import Trajectory
    from ..lang.descriptors import Descriptors
    from ..measuring.measured import Measured

__all__ = ["CHECK_RATE", "BuildResult", "build_file", "build_source", "load_motion"]

#: The safety checks look at the motion at least this often [Hz].
CHECK_RATE = 250.0


@dataclass
class BuildResult:
    """What ``aouc compile`` made of one file. ``document`` is None when it failed."""

    path: str
    lint: FileResult
    diagnostics: list[Diagnostic] = field(default_factory=list)
    compiled: CompileResult | None = None
    declared: Descriptors | None = None
    measured: Measured | None = None
    checks: list = field(default_factory=list)
    #: The document but its samples (see :attr:`document`); None when the build failed.
    header: dict | None = None
    seconds: float = 0.0
    #: With ``fit``: the file's text with the fitted values (None: nothing was fitted).
    fitted_source: str | None = None
    #: The temporary file the process that built it wrote the document into, waiting
    #: for its name (:mod:`~aou_dsl.driver.delivery`); None: nothing staged.
    staged: str | None = field(default=None, repr=False, compare=False)
    _document: dict | None = field(default=None, init=False, repr=False, compare=False)

    @property
    def ok(self) -> bool:
        return self.header is not None and not has_errors(self.diagnostics)

    @property
    def document(self) -> dict | None:
        """The trajectory document (``aou-trajectory/1``); None when the build failed.

        Its samples (lists of floats) are made from the compiled trajectory's arrays when
        the document is first asked for: a program that uses the arrays
        (:attr:`trajectory`), like a robot re-planning as it goes, never pays for them."""
        if self._document is None and self.header is not None and self.compiled is not None:
            from ..compiler.output import with_samples

            self._document = with_samples(self.header, self.compiled.trajectory)
        return self._document

    def drop_samples(self) -> None:
        """Forget the document's lists of samples (they are made again when asked for):
        the arrays travel between processes as raw bytes, lists float by float."""
        self._document = None

    @property
    def trajectory(self) -> Trajectory:
        """The compiled trajectory.

        Raises:
            AouError: the build failed; its diagnostics say why.
        """
        if self.compiled is None or self.compiled.trajectory is None:
            raise AouError(self.diagnostics or diag(
                C305, "the build failed: there is no trajectory", Span.whole_file(self.path)))
        return self.compiled.trajectory


def _with_robot(lint: FileResult, robot: str | None) -> list[Diagnostic]:
    """Point the behaviour at another robot (``--robot``); V109 for an unknown one. What
    is said of the robot then points at the command line, not the file's ``robot`` line."""
    from ..core.robot_specs import ROBOTS, is_robot_file

    if robot is None or lint.behaviour is None:
        return []
    where = Span.whole_file("<command line>")
    if robot not in ROBOTS and not is_robot_file(robot):
        from ..robot.load import unknown_robot

        return [unknown_robot(robot, where)]
    b = lint.behaviour
    spans = {**b.settings.spans, "robot": where}
    lint.behaviour = b.replace(settings=b.settings.replace(robot=robot, spans=spans))
    return []


def _check(res: BuildResult, rate: float, scene: SceneOptions,
           controller: str | None = None) -> dict:
    """The kinematic replay and the controller's view of the motion (joint jerk at its
    rate), as C306/C311 diagnostics and the document's ``checks``."""
    from ..compiler.pipeline import sample
    from ..safety.controllers import controller_checks, describe
    from ..safety.replay import replay

    assert res.compiled is not None
    tr = res.compiled.trajectory
    assert tr is not None
    dense = tr if rate >= CHECK_RATE else sample(res.compiled, CHECK_RATE)
    report = replay(dense, options=scene)
    motion = controller_checks(res.compiled, controller)
    report.checks += motion
    res.checks = report.checks
    for c in report.failed():
        if any(c is m for m in motion):
            res.diagnostics.append(diag(
                C311 if c.name == "joint-jerk" else C306,
                f"{c.name} check failed: {describe(c)}", _span_at(res.compiled, c.time),
                check=c.name, time=c.time, joint=c.joint, value=c.value, limit=c.limit))
            continue
        res.diagnostics.append(diag(
            C306, f"{c.name} check failed at t={c.time:.3f}s: {_what(c)}",
            _span_at(res.compiled, c.time), check=c.name, time=c.time, joint=c.joint,
            value=c.value, limit=c.limit))
    return {"kinematic": report.to_json()}


def _robot_diagnostics(b, opts: BuildOptions) -> list[Diagnostic]:
    """What the build says of its robot (limits from no source, no collision shapes)."""
    from ..robot import robot_diagnostics

    try:
        return robot_diagnostics(b.settings.robot,
                                 collision_check=opts.check and opts.collision_check,
                                 span=b.settings.spans.get("robot", b.span),
                                 package_dirs=opts.package_dirs)
    except AouError as err:
        return list(err.diagnostics)


def build_lint(lint: FileResult, options: BuildOptions | None = None,
               **changes: Any) -> BuildResult:
    """Compile, check and measure a linted file (see the module's docstring). What the
    compiler says once per repeat of a statement is said once, with the count
    (:func:`~aou_dsl.core.repeats.said_once`).

    ``options`` (:class:`~aou_dsl.core.options.BuildOptions`) says how; keyword
    ``changes`` replace some of its fields (``robot="ur5"``, ``check=False``).
    ``collision_check=False`` lets a robot without collision shapes compile; the
    document's ``checks`` then records that self-collision was not checked.
    ``controller`` (``franka``, ``ur``) adds that motion generator's rate and limits to
    the checks (the robot's joint jerk limit at 1 kHz is always checked)."""
    from ..core.repeats import said_once

    opts = (options or BuildOptions()).replace(**changes) if changes else (
        options or BuildOptions())
    from ..fit.amplitude import with_amplitude_fit
    from ..fit.every_change import with_every_change
    from ..fit.reach import with_reach_fit

    def one(linted: FileResult) -> BuildResult:  # a refusal's hint: the value that fits
        res = with_reach_fit(_build_lint(linted, opts), opts.robot, opts.package_dirs)
        return with_amplitude_fit(res, opts.robot, opts.package_dirs)

    if opts.fit:
        from ..fit.rounds import fit_loop

        res = fit_loop(lint, one)
    else:  # the hint of a refusal: every change the file needs, at once
        res = with_every_change(one(lint), one)
    res.diagnostics = said_once(res.diagnostics)
    return res


def _build_lint(lint: FileResult, opts: BuildOptions) -> BuildResult:
    from ..compiler.output import document_header
    from ..compiler.pipeline import CompileOptions
    from ..lang.declared import declared
    from ..lang.descriptors import compare
    from ..measuring.measured import measure
    from ..measuring.recognisers import missing_part

    start = time.perf_counter()
    res = BuildResult(lint.path, lint, list(lint.diagnostics))
    res.diagnostics += _with_robot(lint, opts.robot)
    b, tl = lint.behaviour, lint.timeline
    if has_errors(res.diagnostics) or b is None or tl is None or lint.cv is None:
        return res
    res.diagnostics += _robot_diagnostics(b, opts)
    if has_errors(res.diagnostics):
        return res
    copts = CompileOptions(package_dirs=opts.package_dirs) if opts.rate is None else \
        CompileOptions(rate=opts.rate, package_dirs=opts.package_dirs)
    try:
        attempt, checks = _compile_checked(lint, b, tl, copts, opts)
    except AouError as err:  # a robot file the check reads refuses it (a mesh gone)
        res.diagnostics += err.diagnostics
        res.seconds = time.perf_counter() - start
        return res
    res.compiled = compiled = attempt.compiled
    res.checks = attempt.checks
    res.diagnostics += attempt.diagnostics
    tr = compiled.trajectory if compiled is not None else None
    if checks is None or compiled is None or tr is None:
        res.seconds = time.perf_counter() - start
        return res
    checks_json: dict[str, Any] = checks
    try:
        res.measured = m = measure(tr.with_(path=lint.path))
    except AouError as err:  # measure refuses to report: this file fails, not the batch
        res.diagnostics += err.diagnostics
        res.seconds = time.perf_counter() - start
        return res
    res.declared = want = declared(b, tl)
    explained = {d.refusal.descriptor for d in res.diagnostics
                 if isinstance(d.refusal, AccelerationShort)}
    unread = missing_part({e.kind for e in tl.episodes},
                          {e.kind: e.span for e in reversed(tl.episodes)})
    res.diagnostics += unread  # K802: no plugin pass reads its kind back, so no C310 can
    for mm in compare(want, m.descriptors) if not unread else ():  # judge the motion
        if mm.name in explained:  # C304 said why the arm gives less than declared
            continue
        res.diagnostics.append(diag(
            C310, f"{mm.name}: declared {_fmt(mm.declared)}, measured {_fmt(mm.measured)} "
            "on the compiled trajectory", _span_of(b, mm.name), descriptor=mm.name,
            declared=mm.declared, measured=mm.measured))
    res.header = document_header(
        compiled, measured=m.descriptors.to_json(), declared=want.to_json(),
        cv=lint.cv.to_json(), checks=checks_json | {"gaze_error_deg": round(m.gaze_error, 6)},
        rate=copts.rate)
    res.seconds = time.perf_counter() - start
    return res


def _attempt(lint: FileResult, b, tl, copts, opts: BuildOptions
             ) -> tuple[BuildResult, dict[str, Any] | None]:
    """One compile and, unless ``opts.check`` is False, its checks: a result holding
    their diagnostics, and the document's ``checks`` (None when either failed)."""
    from ..compiler.pipeline import compile_behaviour

    out = BuildResult(lint.path, lint)
    out.compiled = compiled = compile_behaviour(b, copts, tl)
    out.diagnostics += compiled.diagnostics
    if not compiled.ok or compiled.trajectory is None:
        return out, None
    checks: dict[str, Any] = {"kinematic": "skipped (--no-check)"}
    if opts.check:
        from ..robot import load_robot

        checks["collision_checked"] = load_robot(b.settings.robot,
                                                 opts.package_dirs).collision
        checks |= _check(out, copts.rate, opts.scene, opts.controller)
        if has_errors(out.diagnostics):
            return out, None
    return out, checks


def _blames_start(d: Diagnostic) -> bool:
    """An error another joint solution of the start pose may avoid: the start pose
    beyond a joint limit, IK at a joint limit on the way, a failed check (links that
    touch, a joint beyond its range)."""
    return d.severity is Severity.ERROR and (
        d.code in (C302, C306) or (d.code in (C301, C303) and isinstance(
            d.refusal, Unreachable) and d.refusal.time == 0.0))


def _compile_checked(lint: FileResult, b, tl, copts, opts: BuildOptions
                     ) -> tuple[BuildResult, dict[str, Any] | None]:
    """:func:`_attempt`; when it fails in a way the start's joint solution may be to
    blame, again from each other solution of the start pose
    (:func:`~aou_dsl.compiler.branches.start_alternatives`) until one passes. When none
    does, the first failure is said, with what was tried."""

    from ..compiler.branches import start_alternatives

    first, checks = _attempt(lint, b, tl, copts, opts)
    if checks is not None or not any(_blames_start(d) for d in first.diagnostics):
        return first, checks
    tr = first.compiled.trajectory if first.compiled is not None else None
    seeds = start_alternatives(b, tl, opts.package_dirs, None if tr is None else tr.q[0])
    for k, seed in enumerate(seeds, 1):
        other, checks = _attempt(lint, b, tl, replace(copts, start_seed=seed), opts)
        if checks is not None:
            checks["start_configuration"] = {
                "q": list(seed), "why": f"solution {k} of {len(seeds)} other joint "
                "solutions of the start pose; the first failed: "
                + "; ".join(d.message for d in first.diagnostics if _blames_start(d))[:300]}
            return other, checks
    tried = (f"tried the start pose from {len(seeds)} other joint solution(s) (other IK "
             "branches and, on a 7-joint arm, other points of its redundancy, from "
             "postures turned at one joint): none passes" if seeds else
             "no other joint solution of the start pose was found (IK from postures "
             "turned at one joint)")
    first.diagnostics = [replace(d, hint=f"{d.hint}; {tried}" if d.hint else tried,
                                 fields={**d.fields, "start_solutions_tried": len(seeds)},
                                 fix=None)
                         if _blames_start(d) else d for d in first.diagnostics]
    return first, None


def build_source(text: str, path: str = "<string>", options: BuildOptions | None = None,
                 **changes: Any) -> BuildResult:
    """:func:`build_lint` of source text; ``options`` and ``changes`` as there."""
    return build_lint(lint_source(text, path), options, **changes)


def build_file(path: str, options: BuildOptions | None = None, **changes: Any) -> BuildResult:
    """:func:`build_lint` of a file; ``options`` and ``changes`` as there."""
    return build_lint(lint_file(path), options, **changes)


def _what(c) -> str:
    """A failed check in words: what reached what."""
    if c.name.startswith("joint-"):
        return f"{c.joint} reaches {c.value:.4g}, limit {c.limit:.4g}"
    if c.name == "kinematics-agreement":
        return c.detail
    return f"{c.joint}: {c.detail} (distance {c.value:.4g} m)"


def _span_of(b, descriptor: str) -> Span:
    """The statement that declares ``descriptor`` (the file when none does)."""
    from ..lang.declared import source_of

    p = source_of(b, descriptor)
    return p.span if p is not None else b.span


def _fmt(v) -> str:
    return "absent" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))


def _span_at(compiled, t: float | None) -> Span:
    """The source span of the episode running at time ``t``."""
    tr, tl = compiled.trajectory, compiled.timeline
    if t is not None:
        for (_kind, a, b), ep in zip(tr.episodes, tl.episodes, strict=True):
            if a <= t <= b:
                return ep.span
    return compiled.behaviour.span


def load_motion(path: str, *, robot: str | None = None,
                goal: tuple[float, float, float] | str | None = None,
                ee_frame: str | None = None, angle_unit: str | None = None,
                time_unit: str | None = None, package_dirs: tuple[str, ...] = ()
                ) -> Trajectory:
    """A ``.aou`` file compiled (without the safety checks), or a trajectory file read
    (a CSV recording needs ``robot``; ``goal`` and ``ee_frame`` override the file's).

    Raises:
        AouError: the file's diagnostics when it cannot be compiled or read.
    """
    from ..core.options import package_dirs as absolute
    from ..measuring.recording import read_recording

    package_dirs = absolute(package_dirs)
    if path.endswith(".aou"):
        res = build_file(path, robot=robot, check=False, package_dirs=package_dirs)
        if not res.ok:
            raise AouError(res.diagnostics)
        return res.trajectory.with_(path=path)
    return read_recording(path, robot=robot, goal=goal, ee_frame=ee_frame,
                          angle_unit=angle_unit, time_unit=time_unit,
                          package_dirs=package_dirs)
