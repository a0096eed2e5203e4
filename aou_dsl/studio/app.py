"""``aouc studio``: a behaviour in 3D in the browser, its numbers beside it, shaped live.

:class:`Studio` wires the pieces: the :class:`~.engine.Engine` builds, the scene draws
(:mod:`.view3d`), the player and the sliders drive (:mod:`.controls`), the numbers are
shown (:mod:`.plots`), Save writes (:mod:`.edits`), the file is watched (:mod:`.watch`).

The file is the truth: the sliders edit its text (:func:`.edits.apply`), the engine
builds that text, and Save writes the text of the motion shown, so the saved file
compiles to exactly that motion. A text that fails shows its diagnostics and leaves the
last good motion on screen. Nothing is written but the file given, and only on Save
(:mod:`.disk`: never over an edit made on disk since, nor through a link swapped in).

Only the page the command printed drives it: the server answers requests that carry
its address and its per-run token (:mod:`.gate`), and every value a page sends is
checked before it reaches viser or the compiler (:mod:`.serving`).
"""

from __future__ import annotations

import os
import threading
import time
from typing import TYPE_CHECKING, Any

from ..core.diagnostics import AouError, Severity
from .disk import Disk
from .engine import Engine, Motion
from .filing import Filing
from .gate import Gate
from .serving import Served

if TYPE_CHECKING:
    from ..core.trajectory import Trajectory
    from .edits import Origin

__all__ = ["LOCAL", "Studio"]

#: The address the studio binds unless told otherwise: this machine only.
LOCAL = "127.0.0.1"


class Studio(Filing, Served):
    """The studio of one file (a ``.aou`` file, or a recording to play).

    Args:
        path: the ``.aou`` file (or a CSV/JSON/NPZ recording, with ``robot``).
        robot: overrides the file's robot; needed for a CSV recording.
        host, port: where to serve (the next free port when ``port`` is taken).
        compare: a second ``.aou`` file shown ghosted on the same clock.
        watch: reload when the file changes on disk.
        engine: the build session to use (a new :class:`Engine` by default).
        fit: build as ``aouc compile --fit`` does: what the arm cannot give is fitted
            (shown in the page); Save still writes the values of the sliders.
        track: a servo mode (``aouc check --track``'s): the arm as its servos track
            each motion shown, simulated, drawn ghosted beside the plan.
    """

    def __init__(self, path: str, *, robot: str | None = None, host: str = LOCAL,
                 port: int = 8080, compare: str | None = None, watch: bool = True,
                 engine: Engine | None = None, package_dirs: tuple[str, ...] = (),
                 fit: bool = False, track: str | None = None) -> None:
        self.path = path
        self.recording = not path.endswith(".aou")
        self.engine = engine or Engine(robot, package_dirs, fit=fit)
        self.compare_path = compare
        self.track_mode = track
        self.tracked: Any = None  # the shown motion as the servos track it (--track)
        self.host, self.asked_port = host, port
        self._watch = watch
        self.file_text = ""  # the file's text as on disk
        self.base_text = ""  # the text the sliders edit (the file's, or re-synthesized)
        self.shown: Motion | None = None
        self.generation = 0  # counts the motions put on screen
        self._pending: dict[str, float] | None = None
        self._wake = threading.Condition()
        self._closed = False
        self.server: Any = None
        self._marked = 0.0  # when the timeline's marker last moved
        self.drawn: Trajectory | None = None  # the motion playing
        self.previewed = 0  # counts the motions played before their checks
        self._busy = threading.Lock()
        self.gate = Gate(host)  # the per-run token and the check of who asks
        self.disk = Disk(path)
        self.base_bytes = b""  # the file's bytes the sliders' text comes from
        self.shown_base = b""  # ... and those the motion shown comes from (Save's check)

    # --- start and stop -------------------------------------------------------------

    def start(self) -> Studio:
        """Build the file, start serving, draw. Raises AouError when the first build of
        the file fails (there is nothing to show) or a robot cannot be drawn."""
        first = self._first_motion()
        from . import view3d as scene
        from .controls import Player, Sliders
        from .serving import Inbox, open_server

        with _quiet():  # viser prints its own banner: `aouc studio:` says the address
            self.server = open_server(self.gate, self.host, self.asked_port,
                                      f"aou studio: {os.path.basename(self.path)}")
        self.inbox = Inbox(self.server, self._told)
        self.server.scene.set_up_direction("+z")
        # Plain lights, no shadows nor environment map: a laptop without a GPU (or a
        # browser rendering WebGL in software) keeps a smooth frame rate.
        self.server.scene.configure_environment_map(None)
        self.server.scene.configure_default_lights(True, cast_shadow=False)
        self.server.scene.add_light_ambient("/ambient", intensity=0.6)
        scene.add_table(self.server)
        assert first.trajectory is not None
        self.arm = scene.Arm(self.server, self.engine.urdf_path(first.trajectory.robot),
                             "/arm")
        self.ghost: scene.Arm | None = None
        self.other: Motion | None = None
        if self.compare_path:
            self._compare(scene)
        elif self.track_mode:
            self.ghost = scene.Arm(self.server, self.engine.urdf_path(first.trajectory.robot),
                                   "/ghost", ghost=True)
        self.server.gui.configure_theme(control_width="large")
        self.server.initial_camera.position = (1.3, -1.1, 0.9)
        self.server.initial_camera.look_at = (0.3, 0.0, 0.25)
        self.status = self.server.gui.add_markdown("")
        self.player = Player(self.server, self._frame, hold=self._busy.locked)
        self.sliders = Sliders(self.server, self._slid)
        self._panels()
        self._show(first)
        threading.Thread(target=self._builder, name="aou-studio-build", daemon=True).start()
        if self._watch and not self.recording:
            from .watch import Watcher

            self.watcher: Watcher | None = Watcher(
                self.path, lambda: self._guarded(self._changed), robot=self.engine.robot,
                package_dirs=self.engine.package_dirs,
                on_robot_change=lambda: self._guarded(self._robot_changed))
        else:
            self.watcher = None
        return self

    def _first_motion(self) -> Motion:
        if self.recording:
            first = self.engine.read(self.path)
        else:
            self.base_bytes = self.disk.read()
            self.file_text = self.base_text = self.disk.text(self.base_bytes)
            first = self.engine.build(self.file_text, self.path)
        if not first.ok or first.trajectory is None:
            raise AouError([d for d in first.diagnostics if d.severity == Severity.ERROR])
        return first

    def _compare(self, scene) -> None:
        from ..core.files import read_text

        assert self.compare_path is not None
        engine = Engine(self.engine.robot, self.engine.package_dirs, fit=self.engine.fit)
        other = engine.build(read_text(self.compare_path), self.compare_path)
        if not other.ok or other.trajectory is None:
            raise AouError([d for d in other.diagnostics if d.severity == Severity.ERROR])
        self.other = other
        self.ghost = scene.Arm(self.server, self.engine.urdf_path(other.trajectory.robot),
                               "/ghost", ghost=True)
        self.ghost.show(other.trajectory)

    def close(self) -> None:
        self._closed = True
        with self._wake:
            self._wake.notify_all()
        if self.watcher is not None:
            self.watcher.close()
        self.player.close()
        with _quiet():
            self.server.stop()

    # --- the page -------------------------------------------------------------------

    def _panels(self) -> None:
        gui = self.server.gui
        if not self.recording:
            self.save_button = gui.add_button("Save", hint=f"write the values into {self.path}")
            self.save_button.on_click(lambda _: self._guarded(self._save_clicked))
            self.reload_button = gui.add_button(
                "Reload", hint=f"take the text of {self.path} as it is on disk (the values "
                "set here go)")
            self.reload_button.on_click(lambda _: self._guarded(self.reload))
        self.notice = gui.add_html("")  # what the page sent that was not taken as sent
        self.diags = gui.add_html("")
        if self.ghost is not None:
            self.ghost_box = gui.add_checkbox(
                f"Show {os.path.basename(self.compare_path)}", True,
                hint="the compared behaviour, ghosted, on the same clock"
            ) if self.compare_path else gui.add_checkbox(
                "Show the tracked arm", True,
                hint=f"the arm as its servos track the motion ({self.track_mode} mode), "
                "simulated, ghosted")
            ghost = self.ghost
            self.ghost_box.on_update(lambda _: ghost.set_visible(self.ghost_box.value))
        self.fitted = gui.add_html("")  # with --fit: what was fitted to the arm
        with gui.add_folder("Timeline"):
            self.timeline = gui.add_html("")
            self.profile = gui.add_html("")
        with gui.add_folder("Numbers"):
            self.table = gui.add_html("")
            self.cvmap = gui.add_html("")

    def _frame(self, t: float) -> None:
        from .plots import timeline

        try:
            self.arm.pose(t)
            if self.ghost is not None:
                self.ghost.pose(t)
        except RuntimeError:  # the player's last tick as the studio closes: no scene
            if self._closed:
                return
            raise
        now = time.monotonic()
        tr = self.drawn
        if tr is not None and (now - self._marked > 0.2 or not self.player.playing):
            self._marked = now  # 5 Hz is enough for the marker
            self.timeline.content = timeline(tr.episodes, float(tr.t[0]), tr.duration, t)

    def _draw(self, tr: Trajectory) -> None:
        """Play ``tr``: the arm, its path and the timeline (the speed profile follows
        with the numbers)."""
        self.drawn = tr
        self.arm.show(tr)
        if self.track_mode and self.ghost is not None:
            from ..safety.track import track

            self.tracked = track(tr, self.track_mode)
            self.ghost.show(self.tracked.trajectory)
        other = self.other.trajectory if self.other is not None else None
        self.player.set_duration(max(tr.duration, other.duration if other else 0.0))
        self._frame(0.0)

    def _show(self, m: Motion, drawn: bool = False) -> None:
        """Put a good motion on screen (``drawn``: it already plays) with its numbers."""
        from ..media.plot import profile_data
        from . import plots
        from .edits import settable, synth_origin

        assert m.trajectory is not None
        self.shown = m
        self.shown_base = self.base_bytes
        if not drawn:
            self._draw(m.trajectory)
        data = profile_data(m.trajectory)
        self.profile.content = plots.velocity_profile(data.t, data.speed, data.episodes)
        measured = m.measured.descriptors if m.measured is not None else None
        self.table.content = plots.descriptor_table(m.declared, measured)
        if m.cv is not None:
            name = m.behaviour.name if m.behaviour is not None else os.path.basename(m.path)
            self.cvmap.content = plots.cv_map(m.cv, name)
        self.fitted.content = plots.fitted_html(m.diagnostics) if self.engine.fit else ""
        lint = self.engine.session.lint(m.text, m.path) if m.text else None
        if lint is not None and lint.behaviour is not None:
            origin = synth_origin(m.text)
            self.sliders.show(settable(lint.behaviour, lint.timeline),
                              origin.intensity if origin else None)
        self.generation += 1
        self._say(m)

    def _say(self, m: Motion, note: str = "") -> None:
        from . import plots

        shown = [d for d in m.diagnostics if d.severity != Severity.NOTE]
        if not m.ok:
            note = note or ("This value cannot be built; the motion shown is the last "
                            "good one.")
        self.diags.content = plots.diagnostics_html(shown, note)
        s = self.shown
        dur = f"{s.trajectory.duration:.2f} s" if s and s.trajectory is not None else "-"
        last = f"built in {m.seconds:.2f} s" if m.ok else "**the last build failed**"
        if self.tracked is not None:
            import numpy as np

            worst = float(np.degrees(self.tracked.error_max).max())
            last += (f"; ghosted: the arm through its {self.track_mode} servos, "
                     f"largest tracking error {worst:.2g} deg")
        self.status.content = f"**{os.path.basename(self.path)}**: {dur} of motion; {last}"

    # --- shaping ------------------------------------------------------------------

    def _slid(self, values: dict[str, float]) -> None:
        with self._wake:
            self._pending = values
            self._wake.notify_all()

    def _builder(self) -> None:
        """Builds the latest slider values, one at a time."""
        while True:
            with self._wake:
                while self._pending is None and not self._closed:
                    self._wake.wait()
                values, self._pending = self._pending, None
            if values is None:  # closed
                return
            self._guarded(self.set_values, values)

    def _guarded(self, work, *args) -> None:
        """``work(*args)`` on a studio thread: a failure of aou itself is said in the page
        and on stderr, and the studio goes on with the last good motion."""
        try:
            work(*args)
        except Exception as exc:  # noqa: BLE001 - the thread must live on
            import sys

            print(f"aouc studio: internal error: {type(exc).__name__}: {exc} (please "
                  "report it)", file=sys.stderr)
            self.diags.content = ('<div id="aou-diagnostics"><p>internal error: '
                                  f"{type(exc).__name__}; the motion shown is the last good "
                                  "one (see the terminal)</p></div>")

    def set_values(self, values: dict[str, float]) -> Motion:
        """Build the file's text with ``values`` (descriptor -> value in its unit) and
        show it; a text that fails leaves the last good motion on screen."""
        from .controls import INTENSITY
        from .edits import apply, synth_origin

        assert self.shown is not None
        values = dict(values)
        intensity = values.pop(INTENSITY, None)
        origin = synth_origin(self.base_text)
        try:
            if origin is not None and intensity is not None and intensity != origin.intensity:
                text = self._synthesized(origin, intensity)
            else:
                text = apply(self.base_text, values, self.path)
        except AouError as err:
            failed = Motion(self.path, "", tuple(err.diagnostics))
            self._say(failed)
            return failed
        with self._busy:
            tr = self.engine.preview(text, self.path)
            if tr is not None:  # it plays while the same text is checked and measured
                self._draw(tr)
                self.previewed += 1
            m = self.engine.build(text, self.path)
            if m.ok and m.trajectory is not None:
                if intensity is not None and origin is not None and \
                        intensity != origin.intensity:
                    self.base_text = text  # the sliders now shape the new file
                self._show(m, drawn=tr is not None and _same(tr, m.trajectory))
            else:
                if tr is not None and self.shown.trajectory is not None:
                    self._draw(self.shown.trajectory)  # back to the last good motion
                self._say(m)
        return m

    def _synthesized(self, origin: Origin, intensity: float) -> str:
        """The file ``aouc synth`` writes for ``origin`` (a state, or a blend's C-V
        point) at ``intensity``, for the same robot and goal (its values fitted to the
        arm; the build checks them)."""
        from ..synth.synthesis import synthesize

        b = self.shown.behaviour if self.shown is not None else None
        robot = self.engine.robot or (b.settings.robot if b is not None else None)
        goal = b.settings.goal if b is not None and "goal" in b.settings.spans else None
        if origin.point is not None:
            c, v = origin.point
            return synthesize(C=c, V=v, intensity=intensity, robot=robot, goal=goal,
                              verify=False)
        return synthesize(origin.state, intensity=intensity, robot=robot, goal=goal,
                          verify=False)

    def _told(self, text: str) -> None:
        """Say in the page what a page sent that was not taken as sent."""
        import html

        notice = getattr(self, "notice", None)
        if notice is not None:
            notice.content = f'<div id="aou-notice"><p>{html.escape(text)}</p></div>'



def _quiet():
    """Standard output silenced (viser's messages; aou's own go to stderr)."""
    import contextlib
    import io

    return contextlib.redirect_stdout(io.StringIO())


def _same(a: Trajectory, b: Trajectory) -> bool:
    return bool(a.t.shape == b.t.shape and (a.t == b.t).all() and (a.q == b.q).all())
