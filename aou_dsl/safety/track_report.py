"""``--track``: the plan tracked in every servo mode the arm's controller offers, each
tracked motion measured and judged against the behaviour as ``aouc measure --against``
judges a recording (:func:`aou_dsl.measuring.verdict.judge`), and the diagnostics:

- C322 for each descriptor that the plan shows within its tolerance but the arm, in the
  chosen mode, does not: the value it gives, and the modes that keep it;
- C323 when the arm has no servo table and the generic servo stood in.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..core.codes import C322, C323
from ..core.diagnostics import Diagnostic, Span, diag
from ..core.servo_specs import MODES, ServoTable
from ..core.trajectory import Trajectory
from ..lang.primitives import SHIVER as SHIVER_KIND
from ..measuring.verdict import Verdict, judge
from .track import Tracked, arm_servo, track

__all__ = ["AtRisk", "ModeResult", "TrackReport", "track_modes"]

#: How each mode reads in a sentence.
MODE_WORDS = {"position": "plain position set-points",
              "feedforward": "position set-points with velocity feed-forward",
              "torque": "computed torque (set-points, velocity and inverse-dynamics torque)"}


@dataclass(frozen=True)
class ModeResult:
    """One servo mode: the tracked motion and its verdict (None without a behaviour)."""

    mode: str
    tracked: Tracked
    verdict: Verdict | None


@dataclass(frozen=True)
class AtRisk:
    """One descriptor at risk under tracking: what each mode's tracked motion shows of it.

    Attributes:
        name, unit: the descriptor.
        declared: the value judged against (the fitted text's, for a fitted behaviour).
        written: the file's own value when the fit changed it (else equal to ``declared``).
        shown: per mode, ``(measured, share of declared or None, within tolerance)``.
        keeps: the modes within tolerance, in :data:`~aou_dsl.core.servo_specs.MODES`
            order.
    """

    name: str
    unit: str
    declared: float | int | None
    written: float | int | None
    shown: dict[str, tuple[float | int | None, float | None, bool]]
    keeps: tuple[str, ...]

    def to_json(self) -> dict:
        def r(v):
            return round(v, 6) if isinstance(v, float) else v

        return {"descriptor": self.name, "unit": self.unit, "declared": r(self.declared),
                "written": r(self.written), "keeps": list(self.keeps),
                "modes": {m: {"measured": r(v), "share": r(sh), "ok": ok}
                          for m, (v, sh, ok) in self.shown.items()}}


def _shiver_descriptor() -> str:
    """The descriptor of a shiver's amplitude, by its kind in the descriptor table."""
    from ..lang.descriptors import REGISTRY

    return next(d.name for d in REGISTRY.values() if d.kind == SHIVER_KIND
                and d.key == "amplitude")


#: The descriptor a shiver's amplitude is, reported whenever the file declares one.
SHIVER = _shiver_descriptor()


@dataclass(frozen=True)
class TrackReport:
    """The plan tracked in each mode the arm offers.

    Attributes:
        robot: the arm; servo: its table; generic: no table was known.
        selected: the mode ``--servo`` chose (its diagnostics are reported).
        results: one per mode offered, in :data:`~aou_dsl.core.servo_specs.MODES` order.
        plan: the plan judged against the behaviour (None without one).
        duration: the plan's length [s].
        written: for a fitted behaviour, what the file as written declares (the
            descriptors' values before the fit); None when nothing was fitted.
        fitted: the fit's changes (the ``fitted`` list of the trajectory's header).
    """

    robot: str
    servo: ServoTable
    generic: bool
    selected: str
    results: tuple[ModeResult, ...]
    plan: Verdict | None
    duration: float
    written: dict | None = None
    fitted: tuple[dict, ...] = ()

    def result(self, mode: str) -> ModeResult:
        return next(r for r in self.results if r.mode == mode)

    def keeps(self, name: str) -> list[str]:
        """The modes whose tracked motion shows descriptor ``name`` within tolerance."""
        return [r.mode for r in self.results if r.verdict is not None
                and next(w for w in r.verdict.rows if w.name == name).ok]

    def at_risk(self) -> list[AtRisk]:
        """The descriptors a person may not see as declared: each the plan shows within
        tolerance and some mode's tracked motion does not, the shiver whenever one is
        declared, and every descriptor the fit changed from the file's value."""
        if self.plan is None:
            return []
        out = []
        for i, w in enumerate(self.plan.rows):
            rows = [r.verdict.rows[i] for r in self.results if r.verdict is not None]
            written = w.declared if self.written is None else self.written.get(w.name)
            if isinstance(written, float) and isinstance(w.declared, float) \
                    and abs(written - w.declared) <= 1e-9 * max(1.0, abs(written)):
                written = w.declared
            changed = written != w.declared
            lost = w.ok and any(not x.ok for x in rows)
            shiver = w.name == SHIVER and isinstance(w.declared, float) and w.declared > 0
            if not (lost or shiver or changed):
                continue
            shown = {}
            for r in self.results:
                assert r.verdict is not None
                x = r.verdict.rows[i]
                share = (float(x.measured) / float(w.declared)
                         if isinstance(x.measured, (int, float))
                         and isinstance(w.declared, (int, float)) and w.declared else None)
                shown[r.mode] = (x.measured, share, x.ok)
            out.append(AtRisk(w.name, w.unit, w.declared, written, shown,
                              tuple(self.keeps(w.name))))
        return out

    def lost(self, mode: str) -> list:
        """The rows the plan keeps and ``mode``'s tracked motion does not."""
        r = self.result(mode)
        if r.verdict is None or self.plan is None:
            return []
        kept = {w.name for w in self.plan.rows if w.ok}
        return [w for w in r.verdict.rows if not w.ok and w.name in kept]

    def diagnostics(self, robot_span: Span) -> list[Diagnostic]:
        out = []
        if self.generic:
            out.append(diag(C323, f"robot `{self.robot}` has no servo table: tracked with "
                            f"{self.servo.source}", robot_span, hint="give the arm's own "
                            "gains in a robot description's [servo] table (docs/robots.md)"))
        for w in self.lost(self.selected):
            keep = [m for m in self.keeps(w.name) if m != self.selected]
            declared = _text(w.declared, w.unit)
            share = ""
            if isinstance(w.declared, float) and isinstance(w.measured, float) and w.declared:
                share = f" ({w.measured / w.declared:.0%} of it)"
            out.append(diag(
                C322, f"{w.name}: declared {declared}, the arm shows "
                f"{_text(w.measured, w.unit)}{share} under {MODE_WORDS[self.selected]} "
                + ("(it must be absent)" if w.tolerance is None
                   else f"(tolerance +-{_text(w.tolerance)})"), w.span,
                hint=(f"send it with --servo {keep[0]} ({MODE_WORDS[keep[0]]}), which keeps "
                      "it" if keep else "no servo mode of this arm keeps it"),
                descriptor=w.name, declared=w.declared, measured=w.measured,
                mode=self.selected, keeps=keep))
        return out

    def to_json(self) -> dict:
        def mode_json(r: ModeResult) -> dict:
            k = r.tracked
            return {"mode": r.mode, "ok": None if r.verdict is None else r.verdict.ok,
                    "tracking_max_rad": dict(zip(_joints(k), k.error_max.tolist(),
                                                 strict=True)),
                    "tracking_rms_rad": dict(zip(_joints(k), k.error_rms.tolist(),
                                                 strict=True)),
                    "saturated": dict(zip(_joints(k), k.saturated.tolist(), strict=True)),
                    "simulated_s": self.duration,
                    "descriptors": None if r.verdict is None else
                    [w.to_json() for w in r.verdict.rows]}
        return {"robot": self.robot, "servo": self.servo.to_json(), "generic": self.generic,
                "selected": self.selected, "modes": [mode_json(r) for r in self.results],
                "at_risk": [a.to_json() for a in self.at_risk()],
                "fitted": [dict(c) for c in self.fitted]}


def _joints(k: Tracked) -> list[str]:
    from ..robot.load import load_arm

    tr = k.trajectory
    return list(load_arm(tr.robot, tr.ee_frame, tr.package_dirs, tr.ee_definition).joint_names)


def _text(v, unit: str = "") -> str:
    if v is None:
        return "absent"
    return f"{v:.3g}{' ' + unit if unit else ''}"


def track_modes(tr: Trajectory, behaviour=None, *, selected: str = "position",
                servo: ServoTable | None = None, written=None,
                fitted: tuple[dict, ...] = ()) -> TrackReport:
    """Track ``tr`` in every mode the arm's controller offers (and ``selected``).

    Args:
        tr: the plan.
        behaviour: the ``.aou`` file's lint (:class:`~aou_dsl.lang.linter.FileResult`)
            or path to judge each tracked motion against; None to report the tracking
            error alone.
        selected: the mode whose losses are diagnosed.
        servo: the servo table (default: the arm's, else the generic one).
        written: for a fitted behaviour, the lint of the file as written (its declared
            values are reported beside the fitted ones).
        fitted: the fit's changes (the ``fitted`` list of the build's header).
    """
    generic = False
    if servo is None:
        servo, generic = arm_servo(tr.robot, tr.package_dirs)
    modes = [m for m in MODES if m in servo.modes or m == selected]
    plan = judge(tr, behaviour) if behaviour is not None else None
    results = []
    for m in modes:
        k = track(tr, m, servo)
        results.append(ModeResult(m, k, judge(k.trajectory, behaviour)
                                  if behaviour is not None else None))
    fitted = tuple(fitted)
    was = None
    if written is not None and fitted and written.behaviour is not None \
            and written.timeline is not None:
        from ..lang.declared import declared
        from ..lang.descriptors import REGISTRY

        want = declared(written.behaviour, written.timeline)
        was = {name: (want.get(name) or 0) if d.is_count else want.get(name)
               for name, d in REGISTRY.items()}  # a count no statement declares is 0
    return TrackReport(tr.robot, servo, generic, selected, tuple(results), plan, tr.duration,
                       was, fitted)
