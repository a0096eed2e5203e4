"""``aouc plot``: velocity profiles with the episodes shaded, and the C-V map.

matplotlib is imported here only (with the Agg backend: no display needed), so no other
command pays for it. Figures are built from :class:`ProfileData`, computed once from
the trajectory, so what is drawn is exactly what was computed (tests check it).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.codes import R401, R405
from ..core.diagnostics import AouError, Diagnostic, Span, diag
from ..core.trajectory import Trajectory
from ..lang.cv import CANONICAL, CVPoint
from .kind_labels import DEFAULT_COLOUR, labels

__all__ = ["FORMATS", "ProfileData", "cv_figure", "point_labels", "profile_data", "profile_figure",
           "save"]



@dataclass(frozen=True)
class ProfileData:
    """What the velocity-profile figure shows.

    Attributes:
        t: times [s], shape (N,).
        speed: end-effector speed [m/s], shape (N,).
        distance: distance to the goal [m], shape (N,) (NaN without a goal).
        q, qd: joint positions [rad] and velocities [rad/s], shape (N, n).
        lower, upper, vmax: joint limits, shape (n,).
        episodes: (kind, t_start, t_end) per episode: the compiler's, or for a recording
            the ones ``aouc measure`` finds (``measured`` True).
        sight: for a recording with a goal, the line-of-sight angle [deg] over time
            (``sight_t`` [s]), else empty.
        diagnostics: what the figure cannot show (R405: no goal, so no goal distance).
        raw_t, raw_speed: for a recording with noise, its speed by plain differences
            at its own samples (drawn faint behind ``speed``, which is then filtered
            as ``aouc measure`` and ``aouc check`` filter it), else empty.
        noise: the recording's largest joint noise [rad] (0: none).
    """

    title: str
    joint_names: tuple[str, ...]
    t: np.ndarray
    speed: np.ndarray
    distance: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    vmax: np.ndarray
    episodes: tuple[tuple[str, float, float], ...]
    measured: bool = False
    sight_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    sight: np.ndarray = field(default_factory=lambda: np.zeros(0))
    diagnostics: tuple[Diagnostic, ...] = ()
    raw_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    raw_speed: np.ndarray = field(default_factory=lambda: np.zeros(0))
    noise: float = 0.0

    @property
    def has_goal(self) -> bool:
        """Whether the goal distance is known (else its panel is left out)."""
        return bool(np.isfinite(self.distance).any())


#: The most episodes shaded in a profile (a file can list any number; more than a
#: figure can show would take minutes to draw and show nothing).
MAX_SHADED = 400


def profile_data(rec: Trajectory) -> ProfileData:
    """From a trajectory: its compiler episodes are shaded, or, for a recording, the
    episodes ``aouc measure`` finds (with the line of sight). Without a goal there is no
    goal distance, and R405 (a warning) says so.

    Raises:
        AouError: as :func:`aou_dsl.measuring.measured.measure` for a recording that
            cannot be measured.
    """
    from ..robot.batch_fk import batch_fk
    from ..robot.load import load_arm

    arm = load_arm(rec.robot, rec.ee_frame, rec.package_dirs, rec.ee_definition)
    cols = rec.columns(arm.joint_names)
    t = np.asarray(rec.t, float)
    q = np.asarray(rec.q, float)[:, cols]
    pos, _ = batch_fk(arm, q)
    speed = np.linalg.norm(np.gradient(pos, t, axis=0), axis=1)
    qd = np.gradient(q, t, axis=0)
    episodes = rec.episodes
    extra: dict = {}
    if not episodes and len(t) >= 8:
        # A recording's noise: its speed is drawn filtered, as measure and check read it.
        from ..measuring.episodes import COMPUTED_NOISE
        from ..measuring.signal import joint_noise, short_window, smooth, to_grid
        from ..measuring.staircase import dequantised

        jn = joint_noise(t, q)
        sigma = float(jn.effective.max(initial=0.0))
        if sigma > COMPUTED_NOISE:
            q = dequantised(t, q, jn)  # a coarse encoder's staircase, as measure reads it
            w = short_window(sigma, float(np.median(np.diff(t))))
            grid = to_grid(t, q, w * float(np.median(np.diff(t))))
            extra.update(raw_t=t, raw_speed=speed, noise=sigma)
            t, q = grid.t + t[0], grid.q
            pos, _ = batch_fk(arm, q)
            speed = np.linalg.norm(smooth(pos, w, 1, grid.h, order=2), axis=1)
            qd = smooth(q, w, 1, grid.h, order=2)
    if not episodes:
        from ..measuring.measured import measure

        m = measure(rec)
        episodes = tuple((e.kind, e.t_start + t[0], e.t_end + t[0]) for e in m.episodes)
        extra["measured"] = True
        if m.line_of_sight is not None:
            extra["sight_t"] = m.line_of_sight.t + t[0]
            extra["sight"] = m.line_of_sight.angle
    distance = (np.linalg.norm(np.asarray(rec.goal) - pos, axis=1) if rec.goal is not None
                else np.full(len(t), np.nan))
    if rec.goal is None:
        extra["diagnostics"] = (diag(
            R405, "the trajectory has no goal: the plot leaves out the goal-distance "
            "panel and the line of sight",
            Span.whole_file(rec.path), hint="give it with --goal X,Y,Z, or --goal final"),)
    for text, what in ((rec.title, "its behaviour's name"),
                       *((e[0], "an episode's kind") for e in episodes)):
        _check_text(text, what, rec.path)
    return ProfileData(rec.title, arm.joint_names, t, speed, distance, q, qd,
                       arm.lower, arm.upper, arm.vmax, tuple(episodes), **extra)


def _check_text(text: object, what: str, path: str) -> None:
    """Refuse (R401) a string of the file the figure would write that is not text: a
    JSON string may hold a lone surrogate (``"\\ud800"``), which no font draws.

    Raises:
        AouError: R401 naming ``what`` holds it.
    """
    try:
        str(text).encode("utf-8")
    except UnicodeEncodeError as exc:
        bad = str(text)[exc.start]
        raise AouError(diag(R401, f"`{path}`: {what} holds a lone surrogate "
                            f"(U+{ord(bad):04X}), which is not text: it cannot be drawn",
                            Span.whole_file(path),
                            hint="write the name as text (a JSON string of whole "
                                 "characters)")) from None


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def profile_figure(d: ProfileData):
    """Four panels over time: end-effector speed (episodes shaded and labelled, like the
    paper's velocity profiles), goal distance (left out without a goal), joint positions
    and joint velocities as fractions of their limits; for a recording, a fifth: the line
    of sight (how far the hand's forward axis points away from the goal)."""
    plt = _pyplot()
    sight = len(d.sight) > 0
    panels = {"v": 2, "d": 1, "q": 1.3, "qd": 1.3, "sight": 1}
    if not d.has_goal:
        del panels["d"]
    if not sight:
        del panels["sight"]
    fig, axes = plt.subplots(len(panels), 1, sharex=True,
                             figsize=(10, 9 + 1.6 * sight - 1.6 * (not d.has_goal)),
                             gridspec_kw={"height_ratios": list(panels.values())})
    panel = dict(zip(panels, axes, strict=True))
    ax_v, ax_q, ax_qd = panel["v"], panel["q"], panel["qd"]
    if len(d.raw_speed):
        ax_v.plot(d.raw_t, d.raw_speed, color="black", lw=0.6, alpha=0.2,
                  label="raw (differences)")
        ax_v.plot(d.t, d.speed, color="black", lw=1.2,
                  label=f"filtered (noise {d.noise:.2g} rad)")
        # above the panel, where the episodes' labels cannot be under it
        ax_v.legend(fontsize=7, loc="lower right", bbox_to_anchor=(1.0, 1.0), ncol=2,
                    frameon=False, borderaxespad=0.2)
    else:
        ax_v.plot(d.t, d.speed, color="black", lw=1.2, label="end-effector speed")
    # The filtered speed sets the scale: the raw one's noise may reach far above it.
    top = max(float(d.speed.max()), 1e-3) * 1.25
    known = labels()
    for kind, a, b in d.episodes[:MAX_SHADED]:
        shown = known.get(kind)
        for ax in axes:
            ax.axvspan(a, b, color=shown.colour if shown else DEFAULT_COLOUR, alpha=0.15,
                       lw=0)
        ax_v.text((a + b) / 2, top * 0.93, shown.label if shown else kind, ha="center",
                  va="top", fontsize=7,
                  rotation=90 if b - a < 0.08 * (d.t[-1] - d.t[0]) else 0)
    ax_v.set_ylim(0, top)
    ax_v.set_ylabel("speed [m/s]")
    title = d.title or "velocity profile"
    ax_v.set_title((f"{title} (episodes as measured)" if d.measured else title)
                   + ("" if d.has_goal else "; no goal: no goal distance")
                   + (f"; the first {MAX_SHADED} of {len(d.episodes)} episodes shaded"
                      if len(d.episodes) > MAX_SHADED else ""),
                   loc="left" if len(d.raw_speed) else "center")
    if "d" in panel:
        panel["d"].plot(d.t, d.distance, color="#34495e", lw=1.2)
        panel["d"].set_ylabel("goal distance [m]")
    mid = (d.upper + d.lower) / 2
    half = (d.upper - d.lower) / 2
    for j, name in enumerate(d.joint_names):
        ax_q.plot(d.t, (d.q[:, j] - mid[j]) / half[j], lw=1, label=name)
        ax_qd.plot(d.t, d.qd[:, j] / d.vmax[j], lw=1, label=name)
    for ax, label in ((ax_q, "position / range"), (ax_qd, "velocity / limit")):
        ax.axhline(1, color="red", lw=0.8, ls="--")
        ax.axhline(-1, color="red", lw=0.8, ls="--")
        ax.set_ylabel(label)
        ax.set_ylim(-1.1, 1.1)
    ax_q.legend(fontsize=6, ncol=4, loc="lower left")
    if sight:
        panel["sight"].plot(d.sight_t, d.sight, color="#8e44ad", lw=1)
        panel["sight"].set_ylabel("line of sight [deg]")
    axes[-1].set_xlabel("time [s]")
    fig.tight_layout()
    return fig


def point_labels(points: list[tuple[str, CVPoint]], most: int = 3
                 ) -> list[tuple[str, CVPoint]]:
    """One label per place on the map: behaviours at one point (to the hundredth, as the
    map can tell them apart) share it, ``a, b, c +2 more (state)``, instead of being
    printed over each other."""
    places: dict[tuple[float, float], list[tuple[str, CVPoint]]] = {}
    for label, p in points:
        places.setdefault((round(p.C, 2), round(p.V, 2)), []).append((label, p))
    out = []
    for group in places.values():
        names = [label for label, _ in group]
        more = f" +{len(names) - most} more" if len(names) > most else ""
        out.append((f"{', '.join(names[:most])}{more} ({group[0][1].state.value})",
                    group[0][1]))
    return out


def cv_figure(points: list[tuple[str, CVPoint]]):
    """The C-V plane: the five canonical states, the borders of their regions (nearest
    state), and each behaviour's inferred point, labelled."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(6.2, 6))
    # Region borders: the hesitant diamond |C| + |V| = 1, and the axes outside it.
    ax.plot([1, 0, -1, 0, 1], [0, 1, 0, -1, 0], color="#7f8c8d", lw=1)
    for x, y in (([1, 1.2], [0, 0]), ([-1, -1.2], [0, 0]), ([0, 0], [1, 1.2]),
                 ([0, 0], [-1, -1.2])):
        ax.plot(x, y, color="#7f8c8d", lw=1)
    for state, (c, v) in CANONICAL.items():
        ax.scatter([c], [v], s=140, marker="s", color="#bdc3c7", zorder=2)
        ax.annotate(state.value, (c, v), xytext=(0, -16 if v < 0.5 else 10),
                    textcoords="offset points", ha="center", fontsize=9, color="#566573")
    xs = [p.C for _, p in points]
    ys = [p.V for _, p in points]
    ax.scatter(xs, ys, s=40, color="#c0392b", zorder=3)
    for text, p in point_labels(points):  # labelled on the side toward the centre,
        right = p.C > 0.3  # clear of the canonical squares' labels and the plot's edges
        ax.annotate(text, (p.C, p.V), xytext=(-6 if right else 6, -12 if p.V > 0.3 else 5),
                    textcoords="offset points", fontsize=8, ha="right" if right else "left")
    ax.set_xlim(-1.25, 1.25)
    ax.set_ylim(-1.25, 1.25)
    ax.set_aspect("equal")
    ax.axhline(0, color="#ecf0f1", lw=0.5, zorder=0)
    ax.set_xlabel("Commitment C")
    ax.set_ylabel("Vigilance V")
    ax.set_title("Commitment-Vigilance plane")
    fig.tight_layout()
    return fig


#: The figure formats ``aouc plot`` writes.
FORMATS = ("png", "svg", "pdf")

#: What would differ between two saves of one figure, left out: the date, the
#: software's version, and SVG's random ids (drawn from a fixed salt).
_METADATA = {"png": {"Software": None}, "svg": {"Date": None, "Creator": None},
             "pdf": {"CreationDate": None, "ModDate": None, "Creator": None,
                     "Producer": None}}


def save(fig, path: str, inputs=()) -> None:
    """Save atomically and deterministically (the same figure gives the same bytes),
    making the folders missing on the way; never over one of ``inputs``. The figure is
    drawn in memory and the file written whole (:func:`aou_dsl.core.files.write_atomic`), so
    no temporary file is ever left.

    Raises:
        AouError: I502 when the extension is unknown or the folder cannot be written,
            or a code of the output rule (:func:`aou_dsl.core.files.guard_output`).
    """
    import io

    import matplotlib

    from ..core.files import check_output, write_atomic

    fmt = check_output(path, FORMATS, reads=inputs)
    buf = io.BytesIO()
    with matplotlib.rc_context({"svg.hashsalt": "aou", "svg.id": "aou-figure",
                                "pdf.compression": 6}):
        fig.savefig(buf, format=fmt, dpi=120, metadata=_METADATA[fmt])
    write_atomic(path, buf.getvalue(), inputs=inputs)
