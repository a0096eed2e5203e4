"""The language server's one door into the pipeline.

Everything the editor knows of a file comes through these functions; nothing else in
:mod:`aou_dsl.editor` imports the pipeline's stages. Each takes the document's text and
its path (for relative robot files and the diagnostics' spans):

- :func:`lint`: parse, validate, lay out and judge on the C-V model, as ``aouc lint``;
  pure Python, fast enough to run on every keystroke;
- :func:`compile_only`, then :func:`build`: the compiler's diagnostics first, then
  those of the whole ``aouc compile`` (checks and measuring too), for the compile
  diagnostics (C-codes); :func:`shown` then adds the compiled episodes' figures.

Lints and builds go through warm sessions (:class:`~aou_dsl.driver.session.Session`): the
robot models stay loaded, an unchanged text is not linted again, and a build after an
edit re-solves only the episodes the edit changed. Typing and compiling run on different
threads, so each has a session of its own;
- :func:`syntax`: the syntax tree, or None while the file does not parse;
- :func:`format_text`: ``aouc fmt``'s output, or None on a syntax error;
- :func:`rule`: a diagnostic code's registry entry.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from ..core.diagnostics import RULES, AouError, Diagnostic, Rule
from ..core.memo import cached

if TYPE_CHECKING:
    from ..driver.session import Session
    from ..lang.linter import FileResult
    from ..lang.parse import SyntaxTree
    from ..lang.relint import Relinter
    from ..lang.timeline import Episode

__all__ = ["Built", "Shown", "build", "compile_only", "format_text", "lint", "rule", "shown",
           "syntax"]


@dataclass(frozen=True)
class Shown:
    """One compiled episode as the arm moves it: times [s] and peaks of the
    end-effector's translational speed [m/s] and acceleration [m/s^2]."""

    episode: Episode
    t_start: float
    duration: float
    peak_speed: float
    peak_acceleration: float


@dataclass
class Built:
    """What :func:`build` found: the build's diagnostics and, once :func:`shown` has
    run, each episode as compiled (in timeline order)."""

    diagnostics: list[Diagnostic] = field(default_factory=list)
    episodes: list[Shown] = field(default_factory=list)
    _compiled: Any = field(default=None, repr=False)
    _lint: Any = field(default=None, repr=False)


@cached(maxsize=2)
def _session(thread: str) -> Session:
    """The warm session of the typing thread (``"typing"``) or of the compile worker
    (``"compile"``)."""
    from ..driver.session import Session

    return Session()


def lint(text: str, path: str) -> FileResult:
    """``aouc lint`` of the text: diagnostics, behaviour, timeline and C-V point."""
    return _session("typing").lint(text, path)


@cached(maxsize=1)
def _trees() -> Relinter:
    """What the outline's parses keep of each file (on the typing thread): a request
    after an edit parses only the statement the edit changed."""
    from ..lang.relint import Relinter

    return Relinter()


def syntax(text: str, path: str) -> SyntaxTree | None:
    """The syntax tree of the text (a leading byte-order mark dropped), or None while it
    does not parse."""
    return _trees().tree(text, path)


def format_text(text: str, path: str) -> str | None:
    from ..lang.formatter import format_source

    try:
        return format_source(text, path)
    except AouError:
        return None


def rule(code: str) -> Rule | None:
    return RULES.get(code.upper())


def robot_files_key(lint: FileResult | None, robot: str | None) -> tuple:
    """The content of the files of the robot a build of ``lint`` uses (``robot``, else
    the file's own): a build kept for the same text is kept for these files only."""
    from ..robot.load import robot_key

    name = robot or (lint.behaviour.settings.robot if lint is not None
                     and lint.behaviour is not None else None)
    return robot_key(name) if name else ()


def compile_only(text: str, path: str, robot: str | None = None) -> Built | None:
    """The compile alone (no checks, no measuring): the C-codes of the compiler, sooner
    than :func:`build`'s, which then reuses the compile. None when there is nothing to
    compile (lint errors) or another robot than the file's is asked for."""
    from ..compiler.pipeline import compile_behaviour
    from ..core.diagnostics import has_errors

    lint = _session("compile").lint(text, path)
    if robot is not None or lint.behaviour is None or lint.timeline is None \
            or has_errors(lint.diagnostics):
        return None
    try:
        compiled = compile_behaviour(lint.behaviour, timeline=lint.timeline)
    except AouError:  # said again, in its place, by the whole build
        return None
    return Built([*lint.diagnostics, *compiled.diagnostics], _compiled=compiled, _lint=lint)


def build(text: str, path: str, robot: str | None = None, first: Built | None = None
          ) -> Built:
    """``aouc compile`` of the text on ``robot`` (None: the file's own, else panda),
    with the safety checks; nothing is written. ``first`` is :func:`compile_only`'s
    result for the same text and robot, whose compile is used. Raises nothing for a bad
    file: what went wrong is in the diagnostics."""
    from ..driver.builder import build_lint

    if first is not None and first._lint is not None:
        res = build_lint(first._lint, robot=robot)  # its IK and timing are kept: not solved again
    else:
        res = _session("compile").build(text, path, robot=robot)
    return Built(list(res.diagnostics), _compiled=res.compiled)


def shown(built: Built) -> Built:
    """Fill ``built.episodes`` from its trajectory (forward kinematics of every sample:
    done after the diagnostics are out)."""
    compiled, built._compiled = built._compiled, None
    tr = compiled.trajectory if compiled is not None else None
    if compiled is not None and tr is not None and compiled.timeline is not None:
        built.episodes = _shown(compiled.timeline.episodes, tr)
    return built


def _shown(episodes: tuple[Episode, ...], tr) -> list[Shown]:
    import numpy as np

    from ..robot.load import load_arm

    arm = load_arm(tr.robot, tr.ee_frame)
    pos, _ = arm.fk(tr.q)  # compiled trajectories hold exactly the arm's joints
    t = tr.t
    if len(t) > 2:
        vel = np.gradient(pos, t, axis=0)
        speed = np.linalg.norm(vel, axis=1)
        acc = np.linalg.norm(np.gradient(vel, t, axis=0), axis=1)
    else:
        speed = acc = np.zeros(len(t))
    out = []
    for ep, (_, t0, t1) in zip(episodes, tr.episodes, strict=False):
        win = (t > t0) & (t < t1)
        out.append(Shown(ep, float(t0), float(t1 - t0),
                         float(speed[win].max()) if win.any() else 0.0,
                         float(acc[win].max()) if win.any() else 0.0))
    return out
