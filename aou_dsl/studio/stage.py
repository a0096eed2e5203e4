"""``aouc studio SCENARIO.toml``: the perception loop played live in the browser.

:class:`Stage` runs the loop of ``aouc live`` (:class:`aou_dsl.live.loop.Loop`: the
perception, the regulator, every re-plan checked before it reaches the arm) on the wall
clock at the scenario's rate, and shows, about ten times a second:

- the arm following the motion the loop sent it, the target with its tag, the
  occluders and the camera, in 3D;
- what the camera sees (:mod:`.liveview`: the geometric model's view, or the rendered
  camera's frame with ``perception="camera"``), the confidence over the last seconds,
  the state and intensity the arm expresses, and the estimate on the C-V map;
- sliders for the light and for where the target and each occluder are. The
  scenario's timeline plays as ``aouc live`` plays it; once the page moves a slider,
  what it moves stays where the page put it, and the arm answers through the same loop
  (with ``follow``, its goal goes with the target).

The page is served as the studio's (:mod:`.serving`): only the printed address with its
token is answered, and each slider's value is checked and clamped to its range before
the loop sees it.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from .serving import Served

if TYPE_CHECKING:
    from ..live.loop import Loop, Tick
    from ..live.scenario import Scenario
    from ..live.world import Scene

__all__ = ["DRAW_EVERY", "Stage"]

#: How often the page is drawn [s] (the loop itself ticks at the scenario's rate).
DRAW_EVERY = 0.1
#: The loop's clock waits rather than run more than this behind the wall clock [s] (a
#: slow first re-plan, a busy machine): the arm's motion never jumps.
_BEHIND = 0.5
#: Slider ranges of an occluder's centre along x, y, z [m] (widened to hold the file's).
_RANGES = ((-0.2, 1.0), (-0.5, 0.5), (0.0, 0.5))


class Stage(Served):
    """The live studio of one scenario file.

    Args:
        path: the scenario (``.toml``).
        robot: the arm (default panda).
        perception: ``geometric`` (the model) or ``camera`` (rendered, with detection).
        host, port: where to serve (the next free port when ``port`` is taken).
        regulator: the regulator to use (its plans kept); a new one by default.
    """

    def __init__(self, path: str, *, robot: str | None = None, perception: str = "geometric",
                 host: str = "127.0.0.1", port: int = 8080, regulator: Any = None) -> None:
        from .gate import Gate

        self.path, self.robot, self.kind = path, robot or "panda", perception
        self.host, self.asked_port = host, port
        self.gate = Gate(host)
        self._reg = regulator
        self._lock = threading.Lock()
        self._placed: dict[str, tuple[float, float, float]] = {}  # what the page put
        self._light: float | None = None
        self._wrote: dict[int, float] = {}  # what the stage last wrote in each slider
        self._stop = threading.Event()
        self.ticks: deque[Tick] = deque(maxlen=4000)  # the last 40 s at 100 Hz
        self.drawn = 0  # counts the page's redraws
        self.server: Any = None

    # --- start and stop -------------------------------------------------------------

    def start(self) -> Stage:
        """Read the scenario, make every plan, start serving and the loop.

        Raises:
            AouError: the scenario is not one (I507), or no plan compiles.
        """
        from ..live import scenario as scenarios
        from ..live.loop import HYSTERESIS, Loop
        from ..live.regulator import Regulator
        from .app import _quiet
        from .serving import Inbox, open_server

        self.scenario: Scenario = scenarios.load(self.path)
        sc = self.scenario
        reg = self._reg or Regulator(self.robot, sc.goal, hysteresis=HYSTERESIS)
        reg.prepare()  # every re-plan in the loop is then warm
        reg.reset()
        self.perception = self._perception()
        self.loop: Loop = Loop(self.perception, rate=sc.rate, regulator=reg, keep=False,
                               perception_rate=self._camera_rate(), follow=sc.offset)
        with _quiet():
            self.server = open_server(self.gate, self.host, self.asked_port,
                                      f"aou studio: {sc.title or self.path}")
        self.inbox = Inbox(self.server, self._told)
        self._scene3d(reg.robot)
        self._panels()
        self._thread = threading.Thread(target=self._run, name="aou-studio-live", daemon=True)
        self._thread.start()
        return self

    def _perception(self) -> Any:
        if self.kind == "camera":
            from ..live.camera import Camera

            return Camera(self.scene_at)
        from ..live.geometric import Geometric

        return Geometric(self.scene_at)

    def _camera_rate(self) -> float | None:
        from ..live.camera import CAMERA_RATE

        return CAMERA_RATE if self.kind == "camera" else None

    def close(self) -> None:
        from .app import _quiet

        self._stop.set()
        thread = getattr(self, "_thread", None)
        if thread is not None:
            thread.join(timeout=10)
        close = getattr(getattr(self, "perception", None), "close", None)
        if close is not None:
            close()
        if self.server is not None:
            with _quiet():
                self.server.stop()
            self.server = None

    # --- the scene the perception sees ----------------------------------------------

    def scene_at(self, t: float) -> Scene:
        """The scenario's scene at ``t``, with the target, the occluders and the light
        the page placed where it placed them."""
        s = self.scenario.scene_at(t)
        with self._lock:
            placed, light = dict(self._placed), self._light
        if placed:
            s = replace(s, occluders=tuple(replace(b, center=placed.get(b.name, b.center))
                                           for b in s.occluders))
        if "target" in placed:
            s = replace(s, target=placed["target"], target_velocity=(0.0, 0.0, 0.0))
        return s if light is None else replace(s, light=light)

    def place(self, name: str, center: tuple[float, float, float]) -> None:
        """Put the occluder ``name`` (or the ``target``) at ``center`` [m] (what its
        sliders do)."""
        with self._lock:
            self._placed[name] = center

    def set_light(self, light: float) -> None:
        """Set the light (what its slider does)."""
        with self._lock:
            self._light = light

    # --- the page -------------------------------------------------------------------

    def _scene3d(self, robot: str) -> None:
        from ..live.world import CUBE
        from ..robot.load import scene_urdf
        from . import view3d

        srv = self.server
        srv.scene.set_up_direction("+z")
        srv.scene.configure_environment_map(None)
        srv.scene.configure_default_lights(True, cast_shadow=False)
        srv.scene.add_light_ambient("/ambient", intensity=0.6)
        view3d.add_table(srv)
        self.arm = view3d.Arm(srv, scene_urdf(robot, visuals=True), "/arm")
        self._shown: Any = None  # the motion the arm's path shows
        s = self.scenario.scene
        self.target = srv.scene.add_box("/target", color=(190, 190, 190),
                                        dimensions=(CUBE,) * 3, position=s.target)
        self.tag = srv.scene.add_box("/target/tag", color=(20, 20, 20),
                                     dimensions=(0.002, 0.8 * CUBE, 0.8 * CUBE),
                                     position=(-CUBE / 2 - 0.001, 0.0, 0.0))
        self.boxes = {b.name: srv.scene.add_box(f"/occluder/{b.name}", color=(51, 77, 128),
                                                dimensions=tuple(2 * h for h in b.half),
                                                position=b.center)
                      for b in s.occluders}
        self.camera = srv.scene.add_camera_frustum("/camera", fov=s.fov * 3.14159 / 180,
                                                   aspect=4 / 3, scale=0.05,
                                                   color=(40, 40, 40))
        srv.initial_camera.position = (1.2, -1.1, 0.8)
        srv.initial_camera.look_at = (0.4, 0.0, 0.1)
        self._place3d(s)

    def _place3d(self, s: Scene) -> None:
        import numpy as np
        from viser import transforms

        from ..live.world import camera_axes

        self.target.position = s.target
        self.target.wxyz = transforms.SO3.from_z_radians(s.target_yaw - np.pi).wxyz
        for b in s.occluders:
            if b.name in self.boxes:
                self.boxes[b.name].position = b.center
        fwd, right, up = camera_axes(s)
        rot = np.stack([right, -up, fwd], axis=1)  # the frustum looks along its +z
        self.camera.wxyz = transforms.SO3.from_matrix(rot).wxyz
        self.camera.position = s.camera

    def _panels(self) -> None:
        gui = self.server.gui
        gui.configure_theme(control_width="large")
        title = self.scenario.title or self.path
        gui.add_markdown(f"**{title}**: the loop of `aouc live`, playing ({self.kind} "
                         "perception)")
        self.notice = gui.add_html("")
        self.state = gui.add_html("")
        self.view = gui.add_html("")
        with gui.add_folder("Confidence"):
            self.plot = gui.add_html("")
        with gui.add_folder("C-V map"):
            self.cvmap = gui.add_html("")
        s = self.scenario.scene
        self.sliders: dict[str, tuple[Any, ...]] = {}
        with gui.add_folder("Scene"):
            self.light = gui.add_slider("light", 0.0, 2.0, 0.01, round(s.light, 2),
                                        hint="1 a lit lab, 0 dark")
            self.light.on_update(self._lit)
            for name, centre in _movable(s):
                handles = []
                for axis, (lo, hi), v in zip("xyz", _RANGES, centre, strict=True):
                    h = gui.add_slider(f"{name} {axis} [m]", min(lo, v), max(hi, v), 0.005,
                                       round(v, 3), hint=f"where {name}'s centre is")
                    h.on_update(lambda event, name=name: self._moved(name, event))
                    handles.append(h)
                self.sliders[name] = tuple(handles)

    def _moved(self, name: str, event: Any) -> None:
        if event.client is not None:  # the page moved it (the timeline's steps do not)
            self.place(name, tuple(float(h.value) for h in self.sliders[name]))  # type: ignore[arg-type]

    def _lit(self, event: Any) -> None:
        if event.client is not None:
            self.set_light(float(self.light.value))

    def _told(self, text: str) -> None:
        import html

        self.notice.content = f'<div id="aou-notice"><p>{html.escape(text)}</p></div>'

    # --- the loop on the wall clock -------------------------------------------------

    def _run(self) -> None:
        """The loop's thread: a failure of aou itself is said in the page and on stderr
        (the loop then stops; the page stays)."""
        import sys

        try:
            self._play()
        except Exception as exc:  # noqa: BLE001 - said, not lost with the thread
            if self._stop.is_set():
                return
            print(f"aouc studio: internal error: {type(exc).__name__}: {exc} (please "
                  "report it)", file=sys.stderr)
            self._told(f"internal error: {type(exc).__name__}; the loop stopped (see the "
                       "terminal)")

    def _play(self) -> None:
        dt = 1.0 / self.loop.rate
        t, begun, drawn_at = 0.0, time.monotonic(), -1.0
        tk = None
        while not self._stop.is_set():
            now = time.monotonic() - begun
            if now - t > _BEHIND:  # fell behind: the loop's clock waits
                begun += now - t
                now = t
            while t <= now and not self._stop.is_set():
                tk = self.loop.tick(t)
                self.ticks.append(tk)
                t += dt
            if tk is not None and now - drawn_at >= DRAW_EVERY:
                drawn_at = now
                try:
                    self._draw(tk)
                except RuntimeError:  # the server stops as the studio closes
                    if self._stop.is_set():
                        return
                    raise
            self._stop.wait(max(0.0, t - (time.monotonic() - begun)))

    def _draw(self, tk: Tick) -> None:
        """The page at tick ``tk``: the arm, the scene, the view, the numbers."""
        from ..lang.cv import CVPoint
        from ..live.regulator import from_uncertainty
        from . import liveview, plots

        lp = self.loop
        if lp.active is not None:
            if lp.active is not self._shown:
                self._shown = lp.active
                self.arm.show(lp.active)
            self.arm.pose(tk.t - lp.since)
        s = self.scene_at(tk.t)
        self._place3d(s)
        self._follow(s)
        last = getattr(self.perception, "last", None)
        self.view.content = (liveview.camera_png(last.image) if last is not None
                             else liveview.camera_svg(s, tk.evidence.get("visible")))
        sent = [w for w in lp.switches if w.kind != "held"]
        held = lp.switches[-1].reason if lp.switches and lp.switches[-1].kind == "held" \
            and (not sent or lp.switches[-1].t >= sent[-1].t) else ""
        self.state.content = liveview.state_html(tk, held)
        self.plot.content = liveview.confidence_plot(list(self.ticks), tk.t)
        c, v, _ = from_uncertainty(tk.uncertainty)
        self.cvmap.content = plots.cv_map(CVPoint(c, v), f"{tk.state} {tk.intensity:g}")
        self.drawn += 1

    def _follow(self, s: Scene) -> None:
        """The sliders of what the page has not placed follow the timeline. A slider
        whose value is no longer the one the stage last wrote was moved by a page (viser
        calls no callback for a page's message that comes before its page is
        registered): what it moves is placed there."""
        if self._moved_by_page(self.light):
            self.set_light(float(self.light.value))
        with self._lock:
            placed, light = set(self._placed), self._light
        if light is None and abs(self.light.value - s.light) > 0.005:
            self._write(self.light, round(s.light, 2))
        for name, centre in _movable(s):
            handles = self.sliders.get(name, ())
            if [self._moved_by_page(h) for h in handles].count(True):
                self.place(name, tuple(float(h.value) for h in handles))  # type: ignore[arg-type]
            elif name not in placed:
                for h, v in zip(handles, centre, strict=True):
                    if abs(h.value - v) > 0.0025:
                        self._write(h, round(min(max(v, h.min), h.max), 3))

    def _write(self, handle: Any, value: float) -> None:
        self._wrote[id(handle)] = value
        handle.value = value

    def _moved_by_page(self, handle: Any) -> bool:
        """Whether the page moved ``handle`` since the stage last looked."""
        value = handle.value
        moved = value != self._wrote.get(id(handle), value)
        self._wrote[id(handle)] = value
        return moved


def _movable(s: Scene) -> list[tuple[str, tuple[float, float, float]]]:
    """What the page may move: the target and each occluder, with its centre [m]."""
    return [("target", s.target), *((b.name, b.center) for b in s.occluders)]
