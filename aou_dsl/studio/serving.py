"""The studio's viser server behind its door, taking from a page only what it may send.

Two things viser does not offer a hook for, done here in one place:

- **The door** (:class:`~.gate.Gate`): viser serves its page and its websocket through
  one ``websockets`` server whose ``process_request`` it gives itself. While
  :func:`open_server` constructs the server (viser binds its port in the constructor),
  the ``websockets`` ``serve`` that viser calls is wrapped so that the gate's check
  comes before viser's own; once constructed, the wrapper is gone. If viser ever
  serves without going through it, the studio refuses to start (it never runs open).
- **What a page may send** (:class:`Inbox`): a page sends the values of its controls.
  Each message is checked before viser applies it and passes it on to every other
  page: a slider's value must be a finite number and is clamped to the slider's range
  (a count stays a whole number), a checkbox's a boolean, a dropdown's one of its
  options; only a control's value may change (not its range, label or visibility); any
  other kind of message (viser's share link, uploads, ...) is dropped. A value viser
  could not pass on (an integer past 64 bits) would otherwise close every page that
  connects after it.
"""

from __future__ import annotations

import functools
import math
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any

from .gate import Gate

__all__ = ["Inbox", "Served", "open_server"]

#: One server is constructed at a time: the wrapper of ``serve`` is process-wide while
#: it is in place.
_CONSTRUCTING = threading.Lock()


@contextmanager
def _gated(gate: Gate) -> Iterator[list[bool]]:
    """``websockets.asyncio.server.serve`` with ``gate`` in front of its
    ``process_request``, for the time of the block; the list says whether it was used."""
    import websockets.asyncio.server as wss

    used: list[bool] = []
    original = wss.serve

    def serve(*args: Any, process_request: Any = None, **kwargs: Any) -> Any:
        used.append(True)
        return original(*args, process_request=gate.process_request(process_request),
                        **kwargs)

    with _CONSTRUCTING:
        wss.serve = serve  # type: ignore[misc,assignment]
        try:
            yield used
        finally:
            wss.serve = original  # type: ignore[misc]


def open_server(gate: Gate, host: str, port: int, label: str) -> Any:
    """A viser server on ``host``:``port`` (the next free port when taken) that answers
    only the requests ``gate`` passes.

    Raises:
        RuntimeError: viser served without the gate (a version that serves otherwise).
    """
    import viser

    with _gated(gate) as used:
        server = viser.ViserServer(host=host, port=port, verbose=False, label=label)
    if not used:
        server.stop()
        raise RuntimeError("viser served its page without aou's check of who asks: this "
                           "version of viser is not one the studio knows")
    return server


class Served:
    """A page served behind its gate (the studio of a file, the stage of a scenario):
    its viser ``server`` and its :class:`Gate`."""

    server: Any
    gate: Gate

    @property
    def port(self) -> int:
        return int(self.server.get_port())

    @property
    def url(self) -> str:
        """The page's address, with the token without which the studio answers nothing."""
        return self.gate.url(self.port)


class Inbox:
    """The check of every message a page sends to ``server``: see the module's text.
    ``said(text)`` is told what was refused or changed (to show in the page)."""

    def __init__(self, server: Any, said: Callable[[str], None]) -> None:
        from viser import _messages

        self.server, self.said = server, said
        self.refused = 0  # messages dropped or values changed
        try:  # viser's own tables: a version without them is refused, not run open
            ws = server._websock_server
            handlers: dict[type, list[Callable[..., Any]]] = ws._incoming_handlers
            self._handles: dict[str, Any] = server.gui._gui_input_handle_from_uuid
        except AttributeError:
            server.stop()
            raise RuntimeError("viser takes a page's messages otherwise than the studio "
                               "knows: this version of viser cannot be guarded") from None
        update = _messages.GuiUpdateMessage
        self._gui = list(handlers.get(update, ()))
        if self._gui:
            ws.unregister_handler(update)
        ws.register_handler(update, self._update)
        self._kept(ws, handlers)
        ws.on_client_connect(self._connected)

    def _connected(self, conn: Any) -> None:
        """A page connected: of the handlers viser gave its connection (its camera, its
        own controls: the studio has none), only the camera's stays, checked. Runs
        before the connection's first message is read."""
        self._kept(conn, conn._incoming_handlers, gui=False)

    def _kept(self, owner: Any, handlers: dict[type, list[Callable[..., Any]]],
              gui: bool = True) -> None:
        """Of ``owner``'s ``handlers``, drop those of messages a page of the studio does
        not send, and check the camera's before they run (``gui``: keep the controls'
        too, already checked)."""
        for cls in list(handlers):
            name = cls.__name__
            if name == "ViewerCameraMessage":
                inner = list(handlers[cls])
                owner.unregister_handler(cls)
                owner.register_handler(cls, functools.partial(self._camera_moved, inner))
            elif not (gui and name == "GuiUpdateMessage"):
                owner.unregister_handler(cls)

    async def _update(self, client_id: int, message: Any) -> None:
        if not self._checked(message):
            return
        await _each(self._gui, client_id, message)

    async def _camera_moved(self, inner: list[Callable[..., Any]], client_id: int,
                            message: Any) -> None:
        if self._checked_camera(message):
            await _each(inner, client_id, message)

    def _checked_camera(self, message: Any) -> bool:
        m = message
        if not (_vector(m.wxyz, 4) and _vector(m.position, 3) and _vector(m.look_at, 3)
                and _vector(m.up_direction, 3) and _vector((m.fov, m.near, m.far), 3)
                and all(_whole(x) and 0 <= x <= 1 << 16
                        for x in (m.image_height, m.image_width))):
            self.refused += 1
            return False
        return True

    def _checked(self, message: Any) -> bool:
        """Whether ``message`` may go on; it is made to hold the checked value."""
        import viser

        handle = self._handles.get(message.uuid) if isinstance(message.uuid, str) else None
        updates = message.updates
        if handle is None or not isinstance(updates, dict) or set(updates) != {"value"}:
            return self._refuse("the page may change a control's value, nothing else"
                                if handle is not None else "")
        value = updates["value"]
        name = getattr(handle, "label", "a control")
        if isinstance(handle, viser.GuiSliderHandle):
            if not _finite(value):
                return self._refuse(f"{name}: a number was expected, found {_show(value)}")
            lo, hi = handle.min, handle.max
            whole = isinstance(handle.value, int)
            got = float(value)
            kept = min(max(got, float(lo)), float(hi))
            kept = int(round(kept)) if whole else kept
            if kept != got:
                self.refused += 1
                self.said(f"{name}: {_show(value)} is outside the slider's range "
                          f"{lo} to {hi}{' in whole numbers' if whole else ''}: "
                          f"{kept} is used")
            message.updates = {"value": kept}
            return True
        if isinstance(handle, (viser.GuiCheckboxHandle, viser.GuiButtonHandle)):
            if not isinstance(value, bool):
                return self._refuse(f"{name}: true or false was expected, found "
                                    f"{_show(value)}")
            return True
        if isinstance(handle, viser.GuiDropdownHandle):
            if not isinstance(value, str) or value not in handle.options:
                return self._refuse(f"{name}: one of {', '.join(handle.options)} was "
                                    f"expected, found {_show(value)}")
            return True
        return self._refuse(f"{name}: this control takes no value from the page")

    def _refuse(self, text: str) -> bool:
        self.refused += 1
        if text:
            self.said(text + " (not applied)")
        return False


async def _each(handlers: list[Callable[..., Any]], client_id: int, message: Any) -> None:
    import inspect

    for cb in handlers:
        got = cb(client_id, message)
        if inspect.isawaitable(got):
            await got


def _finite(x: Any) -> bool:
    """A real number (not a boolean) that is finite."""
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        return False
    try:
        return math.isfinite(float(x))
    except OverflowError:  # an integer past a float's range
        return False


def _vector(xs: Any, n: int) -> bool:
    """``xs`` is ``n`` finite numbers."""
    return isinstance(xs, (list, tuple)) and len(xs) == n and all(_finite(x) for x in xs)


def _whole(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _show(value: Any) -> str:
    """A value from a page, short enough to say."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
