"""``aouc compile`` as a library: one ``.aou`` file -> a checked, measured trajectory document.

The steps: lint (stop on errors), compile, check the joint limits at every sample,
measure the result with :mod:`aou_dsl.measure` (the declare -> compile -> measure round
trip, recorded in the output), and build the LANGUAGE.md document. Writing is the
caller's, so a failed build leaves nothing behind.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from .diagnostics import Diagnostic, diag, has_errors
from .lint import FileResult, lint_file

if TYPE_CHECKING:  # the numerical stages load only when a build runs
    import numpy as np

    from .compiler.pipeline import CompileResult, Trajectory
    from .measure.descriptors import Measured
    from .measure.recording import Recording

__all__ = ["BuildResult", "Motion", "build_file", "load_motion", "to_recording"]


@dataclass
class BuildResult:
    """What ``aouc compile`` made of one file. ``document`` is None when it failed."""

    path: str
    lint: FileResult
    diagnostics: list[Diagnostic] = field(default_factory=list)
    compiled: CompileResult | None = None
    measured: Measured | None = None
    checks: list = field(default_factory=list)
    document: dict | None = None
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        return self.document is not None and not has_errors(self.diagnostics)

    @property
    def trajectory(self) -> Trajectory:
        """The compiled trajectory; a build that failed has none (ValueError)."""
        if self.compiled is None or self.compiled.trajectory is None:
            raise ValueError(f"{self.path}: the build failed, there is no trajectory")
        return self.compiled.trajectory


def to_recording(trajectory, path: str = "<compiled>"):
    """A compiled trajectory as a :class:`~aou_dsl.measure.recording.Recording`."""
    from .measure.recording import Recording

    tr = trajectory
    return Recording(tr.t, tr.q, tr.joint_names, tr.robot, tr.ee_frame, tr.goal, path)


def _rounded(d: dict) -> dict:
    return {k: (round(v, 6) if isinstance(v, float) else v) for k, v in d.items()}


def build_file(path: str, *, rate: float | None = None, check: bool = True,
               scene=None) -> BuildResult:
    """Lint, compile, check (kinematic replay in PyBullet) and measure one file.

    ``scene`` is a :class:`~aou_dsl.check.scene.SceneOptions` (target size, table height).
    """
    from .check.replay import replay
    from .check.scene import SceneOptions
    from .compiler.output import trajectory_document
    from .compiler.pipeline import CompileOptions, compile_behaviour
    from .declared import compare_descriptors, declared_descriptors
    from .measure.descriptors import measure

    start = time.perf_counter()
    lint = lint_file(path)
    res = BuildResult(path, lint, list(lint.diagnostics))
    if not lint.ok or lint.behaviour is None or lint.cv is None:
        return res
    b = lint.behaviour
    opts = CompileOptions() if rate is None else CompileOptions(rate=rate)
    compiled = compile_behaviour(b, opts)
    res.compiled = compiled
    res.diagnostics += compiled.diagnostics
    if not compiled.ok or compiled.trajectory is None:
        res.seconds = time.perf_counter() - start
        return res
    tr = compiled.trajectory
    checks_json: dict = {"kinematic": "skipped (--no-check)"}
    if check:
        report = replay(tr.robot, tr.t, tr.q, tr.qd, tr.qdd, tr.goal,
                        options=scene or SceneOptions())
        res.checks = report.checks
        checks_json = {"kinematic": report.to_json()}
        for c in report.failed():
            res.diagnostics.append(diag(
                "C306", f"{c.name} check failed at t={c.time:.3f}s: {_what(c)}",
                _span_at(compiled, c.time), check=c.name, time=c.time, joint=c.joint,
                value=c.value, limit=c.limit))
        if has_errors(res.diagnostics):
            res.seconds = time.perf_counter() - start
            return res
    m = measure(to_recording(tr, path))
    res.measured = m
    declared = declared_descriptors(b)
    for name, want, got in compare_descriptors(declared, m.descriptors):
        res.diagnostics.append(diag(
            "C310", f"{name}: declared {_fmt(want)}, measured {_fmt(got)} on the compiled "
            "trajectory", _span_of(b, name), descriptor=name, declared=want, measured=got))
    res.document = trajectory_document(
        compiled,
        measured=_rounded(m.descriptors),
        declared=_rounded(declared),
        cv=lint.cv.to_json(),
        checks=checks_json | {"gaze_error_deg": round(m.gaze_error, 6)},
        rate=opts.rate,
    )
    res.seconds = time.perf_counter() - start
    return res


def _what(c) -> str:
    """A failed check in words: what reached what."""
    if c.name in ("joint-position", "joint-velocity", "joint-acceleration", "joint-torque"):
        return f"{c.joint} reaches {c.value:.4g}, limit {c.limit:.4g}"
    if c.name == "kinematics-agreement":
        return c.detail
    return f"{c.joint}: {c.detail} (distance {c.value:.4g} m)"


def _span_of(b, descriptor: str):
    """The statement that declares ``descriptor`` (the file when none does)."""
    kind = descriptor.split("_")[0]
    plane = kind if kind in ("horizontal", "vertical") else None
    p = b.first("gaze", plane) if plane else b.first(kind)
    return p.span if p is not None else b.span


def _fmt(v) -> str:
    return "absent" if v is None else (f"{v:.4g}" if isinstance(v, float) else str(v))


def _span_at(compiled, t: float | None):
    """The source span of the episode running at time ``t``."""
    tr, tl = compiled.trajectory, compiled.timeline
    if t is not None:
        for (_kind, a, b), ep in zip(tr.episodes, tl.episodes, strict=True):
            if a <= t <= b:
                return ep.span
    return compiled.behaviour.span


@dataclass(frozen=True)
class Motion:
    """The motion in a file, for the commands that replay or draw it.

    Attributes:
        recording: times, joint positions, robot, frame and goal.
        qd, qdd: the file's joint velocities and accelerations in the recording's column
            order, when it has them (compiled trajectories do), else None.
        episodes: ``(kind, t_start, t_end)`` from the compiler, else None.
        title: the behaviour's name, or the file's stem.
    """

    recording: Recording
    qd: np.ndarray | None
    qdd: np.ndarray | None
    episodes: tuple[tuple[str, float, float], ...] | None
    title: str


def load_motion(path: str, *, robot: str | None = None,
                goal: tuple[float, float, float] | None = None,
                ee_frame: str | None = None) -> Motion:
    """A ``.aou`` file compiled (without the safety checks), or a trajectory file read
    (a CSV recording needs ``robot``; ``goal`` and ``ee_frame`` override the file's).

    Raises:
        AouError: the file's diagnostics when it cannot be compiled or read.
    """
    import json
    import os

    import numpy as np

    from .diagnostics import AouError
    from .measure.recording import read_recording

    if path.endswith(".aou"):
        res = build_file(path, check=False)
        if not res.ok:
            raise AouError(res.diagnostics)
        tr = res.trajectory
        title = res.lint.behaviour.name if res.lint.behaviour else path
        return Motion(to_recording(tr, path), tr.qd, tr.qdd, tr.episodes, title)
    rec = read_recording(path, robot=robot, goal=goal, ee_frame=ee_frame)
    qd = qdd = None
    episodes = None
    if path.endswith(".json"):
        with open(path, encoding="utf-8") as fh:
            doc = json.load(fh)
        if "qd" in doc and "qdd" in doc:
            qd, qdd = np.asarray(doc["qd"], float), np.asarray(doc["qdd"], float)
            if qd.shape != rec.q.shape or qdd.shape != rec.q.shape:
                qd = qdd = None  # malformed derivatives: recompute them from q
        if doc.get("episodes"):
            episodes = tuple((e["kind"], e["t_start"], e["t_end"]) for e in doc["episodes"])
    return Motion(rec, qd, qdd, episodes, os.path.splitext(os.path.basename(path))[0])
