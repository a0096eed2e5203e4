"""Writing a synthesized behaviour as ``.aou`` source: statements printed by their kinds
(:mod:`aou_dsl.lang.primitives`), each preceded by comments saying where its values came from."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..fit.rounding import significant
from ..fit.search import DIGITS
from ..lang.ir import State
from ..lang.primitives import KINDS, SHIVER
from .arm_fit import MARGIN, SHIVER_F, goal_line, robot_line
from .kind_recipes import descriptors, slots
from .recipe import slot_of

if TYPE_CHECKING:
    from ..core.diagnostics import Diagnostic
    from .arm_fit import Limits
    from .recipe import Recipe

__all__ = ["render"]


def _comment(name: str, value: float, unit: str, note: str) -> str:
    shown = f"{value:g}" + (f" {unit}" if unit else "")
    return f"# {name} {shown}: {note.lstrip('; ')}"


def _statement(r: Recipe, kind: str, plane: str | None) -> list[str]:
    """The comments and the statement of one slot (nothing when it is absent)."""
    node = r.node(kind, plane)
    if node is None or not node.count:
        return []
    out = ["", *(_comment(d.name, r.value(d), d.unit, r.notes[d.name])
                 for d in descriptors()
                 if slot_of(d) == (kind, plane) and d.name in r.notes)]
    if KINDS[kind].translation:
        out.append(_comment("speed cap", node.v, "m/s", "the language default (the study "
                            "gives none)"))
    if kind == SHIVER and SHIVER_F in r.notes:
        out.append(_comment(SHIVER_F, node.f, "Hz", r.notes[SHIVER_F]))
    return [*out, KINDS[kind].format(node)]


def render(r: Recipe, state: State, intensity: float, limits: Limits, *,
           point: tuple[float, float, dict[State, float]] | None = None,
           used: float | None = None, why: Diagnostic | None = None) -> str:
    """The file's text. ``point`` is the C-V point and blend weights a blend came from;
    ``used`` the intensity actually used, when the arm needed another one than asked for
    (``why``: the failure of a stronger one)."""
    anchor = ("inactive was not a stimulus of the study: the shipped hold at every intensity"
              if state is State.INACTIVE else f"intensity 0.5 is the study's {state} stimulus")
    lines = [f"# {state} at intensity {intensity:g}, written by `aouc synth`; {anchor}.",
             "# Each comment says where a value came from (docs/synthesis.md)."]
    if point is not None:
        c, v, w = point
        shown = ", ".join(f"{s} {x:.2f}" for s, x in sorted(w.items(), key=lambda i: -i[1]))
        lines.append(f"# C-V point ({c:+.2f}, {v:+.2f}), nearest state {state}: a blend of "
                     f"{shown} (barycentric weights, sharpened until it reads as {state}).")
    if used is not None and used > intensity:
        lines.append(f"# Intensity raised to {used:g}: on {limits.robot} a weaker {state} "
                     f"would not read as {state}.")
    if used is not None and used < intensity:
        cause = f" ({why.code}: {why.message})" if why is not None else ""
        lines.append(f"# Intensity lowered to {used:g}: a stronger {state} fails on "
                     f"{limits.robot}{cause}.")
    where = ("on the probe's line, less on this file's path"
             if limits.accel < significant(MARGIN * limits.reached, DIGITS) else "on this reach")
    lines.append(f"# Fitted to {limits.robot}: accelerations up to {limits.accel:g} m/s^2 "
                 f"(its joints reach about {limits.reached:.2g} m/s^2 {where}).")
    lines += [f"behaviour {state}_synth : {state}", robot_line(limits.robot)]
    if limits.goal is not None:
        lines.append(goal_line(limits.goal).rstrip("\n"))
    for kind, plane in slots():
        lines += _statement(r, kind, plane)
    return "\n".join(lines) + "\n"
