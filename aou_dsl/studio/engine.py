"""The studio's one door to the pipeline: a text compiled for a robot, and measured.

Everything the studio shows comes from an :class:`Engine`: it lints, compiles, checks
and measures a ``.aou`` text exactly as ``aouc compile`` does, through a warm
:class:`~aou_dsl.driver.session.Session` (the arms it has loaded stay loaded, and a slider
that changes one value re-solves only the episodes that value changes), or reads and
measures a recording, and keeps the last good result, so a text that fails leaves the
motion before it on screen.

The surface is small (:meth:`Engine.build`, :meth:`Engine.preview`, :meth:`Engine.read`,
:attr:`Engine.last_good`, :meth:`Engine.urdf_path`). Builds are serialised: the studio's
callbacks run on several threads, the pipeline's native libraries want one at a time.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ..core.diagnostics import AouError, Diagnostic, has_errors

if TYPE_CHECKING:
    from ..core.trajectory import Trajectory
    from ..lang.cv import CVPoint
    from ..lang.descriptors import Descriptors
    from ..lang.ir import Behaviour
    from ..measuring.measured import Measured

__all__ = ["Engine", "Motion"]


@dataclass(frozen=True)
class Motion:
    """One build or reading: what the studio shows.

    Attributes:
        path: the file it came from; text: the ``.aou`` text built ("" for a recording).
        diagnostics: everything the pipeline said (errors, warnings, notes).
        trajectory, measured: the motion and its eleven measured descriptors (None when
            the build failed).
        declared: the descriptors the file declares; behaviour: its IR (None for a
            recording or a text that does not lint); cv: the file's C-V point.
        seconds: how long the build took.
        fitted: with ``fit``, the text the motion was built from when a value was
            fitted to the arm (None: nothing was).
    """

    path: str
    text: str
    diagnostics: tuple[Diagnostic, ...]
    trajectory: Trajectory | None = None
    measured: Measured | None = None
    declared: Descriptors | None = None
    behaviour: Behaviour | None = None
    cv: CVPoint | None = None
    seconds: float = 0.0
    recorded: bool = field(default=False)
    fitted: str | None = None

    @property
    def ok(self) -> bool:
        return self.trajectory is not None and not has_errors(list(self.diagnostics))


class Engine:
    """Builds for one robot (``robot`` overrides the files' ``robot`` line; None keeps
    it), remembering the last good :class:`Motion`. With ``fit``, it builds as
    ``aouc compile --fit`` does: a value the arm cannot give is fitted (C314 warnings),
    the motion is the fitted text's, and :attr:`Motion.text` stays the text asked for."""

    def __init__(self, robot: str | None = None, package_dirs: tuple[str, ...] = (),
                 fit: bool = False) -> None:
        from ..core.options import BuildOptions
        from ..driver.session import Session

        self.robot = robot
        self.fit = fit
        self.session = Session(BuildOptions(robot=robot, package_dirs=package_dirs, fit=fit))
        self.package_dirs = self.session.options.package_dirs
        self.last_good: Motion | None = None
        self.last: Motion | None = None
        self._lock = threading.Lock()

    def build(self, text: str, path: str) -> Motion:
        """Lint, compile, check and measure ``text`` (named ``path`` in diagnostics).
        Never raises for a problem of the text: it is in the diagnostics."""
        start = time.perf_counter()
        with self._lock:
            res = self.session.build(text, path)
        lint = res.lint
        motion = Motion(
            path, text, tuple(res.diagnostics),
            trajectory=res.compiled.trajectory if res.ok and res.compiled else None,
            measured=res.measured if res.ok else None, declared=res.declared,
            behaviour=lint.behaviour, cv=lint.cv, seconds=time.perf_counter() - start,
            fitted=res.fitted_source)
        return self._keep(motion)

    def preview(self, text: str, path: str) -> Trajectory | None:
        """The motion ``text`` compiles to, before the safety checks and the measurement
        (None when it does not compile): the studio plays it while :meth:`build` checks
        and measures the same text. The compiler is deterministic, so :meth:`build`
        makes this very motion; only a check it fails can take it off screen."""
        from ..compiler.pipeline import CompileOptions, compile_behaviour
        from ..fit.plan import FITTED

        with self._lock:
            lint = self.session.lint(text, path)
            b = lint.behaviour
            if not lint.ok or b is None or lint.timeline is None:
                return None
            if self.robot is not None:
                b = b.replace(settings=b.settings.replace(robot=self.robot))
            try:
                res = compile_behaviour(b, CompileOptions(package_dirs=self.package_dirs),
                                        timeline=lint.timeline)
            except AouError:  # an arm that cannot be loaded: build() says why
                return None
        if self.fit and any(d.code in FITTED for d in res.diagnostics):
            return None  # the motion shown is the fitted one: build() makes it
        return res.trajectory if res.ok else None

    def read(self, path: str) -> Motion:
        """A recording (CSV, JSON, NPZ) read for ``robot`` and measured: its episodes are
        the ones measured (not any the file carries); without a goal, the goal is the
        hand's last position."""
        from ..driver.builder import load_motion as read_trajectory
        from ..measuring.measured import measure

        start = time.perf_counter()
        try:
            with self._lock:
                tr = read_trajectory(path, robot=self.robot, package_dirs=self.package_dirs)
                if tr.goal is None:  # the hand's last position, as `--goal final`
                    tr = read_trajectory(path, robot=self.robot, goal="final",
                                         package_dirs=self.package_dirs)
                m = measure(tr)
        except AouError as err:
            return self._keep(Motion(path, "", tuple(err.diagnostics)))
        episodes = tuple((e.kind, e.t_start + m.t_origin, e.t_end + m.t_origin)
                         for e in m.episodes)
        tr = tr.with_(episodes=episodes)
        motion = Motion(path, "", tuple(m.diagnostics), trajectory=tr, measured=m,
                        cv=m.cv, seconds=time.perf_counter() - start, recorded=True)
        return self._keep(motion)

    def _keep(self, motion: Motion) -> Motion:
        self.last = motion
        if motion.ok:
            self.last_good = motion
        return motion

    def urdf_path(self, robot: str) -> str:
        """The URDF of ``robot`` with its visual meshes, its ``package://`` paths resolved
        as the compiler resolves them (absolute) and the end-effector frame aou adds: the
        file the checks and ``aouc render`` load.

        Raises:
            AouError: V109 when a mesh cannot be found.
        """
        from ..robot.load import scene_urdf

        with self._lock:
            return scene_urdf(robot, visuals=True, package_dirs=self.package_dirs)
