"""The studio's controls: the player (play, pause, scrub, speed, loop) and one slider per
descriptor the file sets.

The player keeps the clock: a thread advances it about 30 times a second while playing
and calls ``on_frame(t)``; scrubbing the time slider in the page moves it. A slider's
value is sent to ``on_change`` as the page sends it; the studio compiles the latest one
when it is free (a value dragged past while a build runs is skipped, the one let go of
is built).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

from .kind_controls import RANGES, descriptor_of, range_of

__all__ = ["INTENSITY", "RANGES", "Player", "Sliders", "slider_range"]
_FPS = 30.0
#: The time slider follows the clock every this many frames.
_SLIDER_EVERY = 6


#: The slider of a synthesized file's intensity.
INTENSITY = "intensity"


def _hint(name: str) -> str:
    if name == INTENSITY:
        return "write the file again as `aouc synth` would at this intensity"
    return f"{name} [{descriptor_of(name).unit or 'count'}]"


def slider_range(name: str, value: float) -> tuple[float, float, float]:
    """The range of ``name``'s slider (:func:`.kind_controls.range_of`), widened to hold
    the file's ``value``."""
    lo, hi, step = (0.0, 1.0, 0.05) if name == INTENSITY else range_of(name)
    return min(lo, value), max(hi, value), step


class Player:
    """The clock of the motion shown, and its controls in the page. While ``hold()`` is
    true (a build under way) the clock runs but no frame is drawn: the build gets the
    processor."""

    def __init__(self, server: Any, on_frame: Callable[[float], None],
                 hold: Callable[[], bool] = lambda: False) -> None:
        self.server, self.on_frame, self.hold = server, on_frame, hold
        self.duration = 0.0
        self.t = 0.0
        self.playing = True
        self._stop = threading.Event()
        self._lock = threading.Lock()
        gui = server.gui
        with gui.add_folder("Play"):
            self.button = gui.add_button("Pause")
            self.time = gui.add_slider("Time [s]", 0.0, 1.0, 0.01, 0.0)
            self.speed = gui.add_dropdown("Speed", ("0.25", "0.5", "1", "2"),
                                          initial_value="1")
            self.loop = gui.add_checkbox("Loop", True)
        self.button.on_click(lambda _: self.toggle())
        self.time.on_update(self._scrubbed)
        self._thread = threading.Thread(target=self._run, name="aou-studio-player",
                                        daemon=True)
        self._thread.start()

    def set_duration(self, duration: float) -> None:
        """A new motion: the time slider spans it; the clock starts again."""
        with self._lock:
            self.duration = duration
            self.t = 0.0
        self.time.max = max(round(duration, 2), 0.01)
        self.time.value = 0.0

    def toggle(self) -> None:
        self.playing = not self.playing
        self.button.label = "Pause" if self.playing else "Play"

    def seek(self, t: float) -> None:
        """Move the clock to ``t`` [s from the start] and draw that moment."""
        with self._lock:
            self.t = min(max(t, 0.0), self.duration)
        self.on_frame(self.t)

    def _scrubbed(self, event: Any) -> None:
        if event.client is not None:  # the page moved it (the player's own steps do not)
            self.seek(float(self.time.value))

    def _run(self) -> None:
        last = time.perf_counter()
        tick = 0
        while not self._stop.wait(1.0 / _FPS):
            tick += 1
            now = time.perf_counter()
            dt, last = now - last, now
            if not self.playing or self.duration <= 0:
                continue
            if self.hold():  # a new motion is being built: its frames come next
                continue
            with self._lock:
                self.t += dt * float(self.speed.value)
                if self.t > self.duration:
                    self.t = self.t % self.duration if self.loop.value else self.duration
                t = self.t
            self.on_frame(t)
            if tick % _SLIDER_EVERY == 0:  # the page's widgets need not follow every frame
                self.time.value = round(t, 2)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=2)


class Sliders:
    """One slider per descriptor the file sets; ``on_change(values)`` with all of them
    (name -> value in the descriptor's unit) when the page moves one."""

    def __init__(self, server: Any, on_change: Callable[[dict[str, float]], None]) -> None:
        self.server, self.on_change = server, on_change
        self.folder = server.gui.add_folder("Shape it")
        self.handles: dict[str, Any] = {}

    def show(self, values: dict[str, float | int], intensity: float | None = None) -> None:
        """Sliders for ``values`` (made again when the set of descriptors changes), and
        for the ``intensity`` of a file ``aouc synth`` wrote (None: none)."""
        if intensity is not None:
            values = {INTENSITY: intensity, **values}
        fits = all(self.handles[n].min <= v <= self.handles[n].max
                   for n, v in values.items() if n in self.handles)
        if set(values) != set(self.handles) or not fits:
            for h in self.handles.values():
                h.remove()
            self.handles = {}
            with self.folder:
                for name, v in values.items():
                    lo, hi, step = slider_range(name, v)
                    count = name != INTENSITY and descriptor_of(name).is_count
                    h = self.server.gui.add_slider(
                        name, int(lo) if count else lo, int(hi) if count else hi,
                        int(step) if count else step, int(v) if count else float(v),
                        hint=_hint(name))
                    h.on_update(self._moved)
                    self.handles[name] = h
            return
        for name, v in values.items():
            count = name != INTENSITY and descriptor_of(name).is_count
            self.handles[name].value = int(v) if count else float(v)

    def values(self) -> dict[str, float]:
        return {name: h.value for name, h in self.handles.items()}

    def _moved(self, event: Any) -> None:
        if event.client is not None:
            self.on_change(self.values())
