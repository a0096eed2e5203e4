"""A warm session: the pipeline kept in one process between runs, for tools that run it
again and again on small changes (an editor linting on every keystroke, a studio
recompiling on every slider move, a worker building file after file).

A :class:`Session` keeps what is slow to make and does not change between runs: the
parser (built once per process), every arm it has loaded (the robot loader caches by
name and package folders; :meth:`Session.warm` loads one ahead), and the last results of
each stage, keyed by that stage's inputs:

- ``lint``: by the text and its path; a changed text of a file is linted from the
  statements kept of its last lints, so an edit parses only what it changed;
- ``build`` (compile, check, measure): by the linted behaviour and timeline (their values
  and source positions, which the build's diagnostics point at), the file's path, the
  :class:`~aou_dsl.core.options.BuildOptions` and the content of the robot's files (its
  description, URDF and meshes: :func:`~aou_dsl.robot.load.robot_key`). A change that
  leaves them as they were (a comment at the end of a line, trailing spaces) lints again
  but builds nothing; a changed descriptor, or a robot file edited on disk, builds again.

Below a session, every cache of the process is in one registry
(:mod:`aou_dsl.core.memo`), each keyed by what its result depends on, files by their
content: :meth:`Session.stats` tells what each holds, :meth:`Session.clear` empties them
all, after which a build is the very build of a new process.

A session is not shared between threads without a lock of the caller's; each worker
process of a pool holds its own.
"""

from __future__ import annotations

import os
from collections.abc import Hashable
from typing import TYPE_CHECKING, Any

from ..core.memo import CacheStats, Table
from ..core.memo import clear as clear_caches
from ..core.memo import stats as cache_stats
from ..core.options import BuildOptions

if TYPE_CHECKING:
    from ..core.trajectory import Trajectory
    from ..lang.linter import FileResult
    from ..measuring.measured import Measured
    from .builder import BuildResult

__all__ = ["Session", "warm"]


#: A small behaviour built once by each worker before its first file: the parser, the
#: robot, the compiler's caches, the checks' scene and the measurement all warm.
_WARM = "approach\npause 1.25s x2\nretreat 0.06m a=0.12\n"


def warm(robots: tuple[str, ...] = ("panda",), options: BuildOptions | None = None) -> None:
    """A worker's start: one thread for numerical libraries (the pool already uses every
    core), then a small behaviour built for each of ``robots`` with ``options``."""
    for var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    from .builder import build_source

    for r in robots:  # a robot this behaviour does not suit is simply less warm
        build_source(_WARM, "<warm-up>", options, robot=r)


class _Kept(Table):
    """The last ``size`` results of one stage of one session, most recent last."""

    def get_or(self, key: Hashable, make: Any) -> Any:
        miss = _Kept
        value = self.get(key, miss)
        if value is miss:
            value = make()
            self.put(key, value)
        return value


class Session:
    """The pipeline kept warm: ``text -> lint -> layout -> compile -> check -> measure``,
    re-running only the stages whose inputs changed.

    Args:
        options: how builds are made unless a call says otherwise.
        keep: how many results of each stage are kept.

    Example::

        session = Session(BuildOptions(robot="panda"))
        session.warm()
        res = session.build(text, "hesitant.aou")   # compiled, checked, measured
        res = session.build(text + "# note\\n", "hesitant.aou")  # linted again only
    """

    def __init__(self, options: BuildOptions | None = None, *, keep: int = 16):
        self.options = options or BuildOptions()
        from ..lang.relint import Relinter

        self._keep = keep
        self._lints = _Kept("session.lint", keep)
        self._relinter = Relinter(keep)
        self._builds = _Kept("session.build", keep)
        self.runs = {"lint": 0, "build": 0}

    def clear(self) -> None:
        """Forget every kept result, this session's and every cache of the process
        (:func:`aou_dsl.core.memo.clear`): the next build is made from nothing, as a new
        process makes it. The caches themselves never hold a result made from a robot
        file since edited; this is for a figure of a cold pipeline, or memory."""
        from ..lang.relint import Relinter

        self._lints.clear()
        self._builds.clear()
        self._relinter = Relinter(self._keep)
        clear_caches()

    def stats(self) -> dict[str, CacheStats]:
        """Per cache, by name: hits, misses, entries, size bound and bytes (about), of
        this session's stages (``session.lint``, ``session.build``) and of every cache
        of the process (:func:`aou_dsl.core.memo.stats`)."""
        return {"session.lint": self._lints.stats(), "session.build": self._builds.stats(),
                **cache_stats()}

    def warm(self, robot: str | None = None) -> None:
        """Load ``robot`` (the options' robot, else the Panda) and run every stage once
        on a small behaviour, so that the first real build pays no start-up."""
        warm((robot or self.options.robot or "panda",), self.options)

    def lint(self, text: str, path: str = "<string>") -> FileResult:
        """The lint of ``text`` (named ``path`` in diagnostics), kept for the same text.
        A changed text is linted from the statements it kept of the file's last lints
        (:class:`~aou_dsl.lang.relint.Relinter`): only what the edit changed is parsed
        and read again, and the result is the full lint's."""

        def run() -> FileResult:
            self.runs["lint"] += 1
            return self._relinter.lint(text, path)

        return self._lints.get_or((path, text), run)

    def build(self, text: str, path: str = "<string>", options: BuildOptions | None = None,
              **changes: Any) -> BuildResult:
        """Lint, compile, check and measure ``text`` with the session's options (or
        ``options``, with ``changes``), re-using the last build of the same behaviour."""
        return self._build(self.lint(text, path), path, options, changes)

    def _build(self, linted: FileResult, path: str, options: BuildOptions | None,
               changes: dict[str, Any]) -> BuildResult:
        """:meth:`build` of a lint of the text."""
        from .builder import build_lint

        opts = options or self.options
        if changes:
            opts = opts.replace(**changes)
        if linted.behaviour is None or linted.timeline is None:
            return build_lint(linted, opts)  # refused: nothing to compile, nothing kept

        def run() -> BuildResult:
            self.runs["build"] += 1
            return build_lint(_fresh(linted), opts)

        from ..robot.load import robot_key

        robot = opts.robot or linted.behaviour.settings.robot
        key = (_behaviour_key(linted), path, opts, robot_key(robot, opts.package_dirs))
        return self._builds.get_or(key, run)

    def build_file(self, path: str, options: BuildOptions | None = None,
                   **changes: Any) -> BuildResult:
        """:meth:`build` of a file's text; a file that cannot be read is a result with
        its I501 diagnostic, as :func:`~aou_dsl.driver.builder.build_file` gives. The
        file's lint is the one built from (a lint of the same text is the same lint: it
        is not made twice)."""
        from ..lang.linter import lint_file

        return self.build_linted(lint_file(path), options, **changes)

    def build_linted(self, linted: FileResult, options: BuildOptions | None = None,
                     **changes: Any) -> BuildResult:
        """:meth:`build_file` of a file already linted (``lint_file`` of its path): the
        same result, without linting it again."""
        from ..lang.linter import TRAJECTORY_EXTENSIONS
        from .builder import build_lint

        path = linted.path
        if linted.source is None or linted.behaviour is None:
            opts = options or self.options
            return build_lint(linted, opts.replace(**changes) if changes else opts)
        if path.lower().endswith(TRAJECTORY_EXTENSIONS):  # lint_file's hint for those
            return self.build(linted.source, path, options, **changes)  # is not the text's
        return self._build(linted, path, options, changes)

    def measure(self, trajectory: Trajectory) -> Measured:
        """The eleven descriptors of a trajectory (measuring keeps no state to reuse)."""
        from ..measuring.measured import measure

        return measure(trajectory)


def _behaviour_key(linted: FileResult) -> Hashable:
    """What a build of a linted file depends on: its behaviour and timeline as values
    (their reprs: frozen records of the file's numbers and spans, without identities)."""
    return repr(linted.behaviour), repr(linted.timeline), repr(linted.cv)


def _fresh(linted: FileResult) -> FileResult:
    """A copy a build may change (``--robot`` re-points its behaviour) without touching
    the lint the session keeps."""
    import copy

    return copy.copy(linted)
