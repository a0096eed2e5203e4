"""``aouc studio``: see a behaviour in 3D in the browser, its numbers beside it, and
shape it live (the ``studio`` extra: viser, yourdfpy, watchfiles).

- :mod:`.engine`: the one door to the pipeline (build, measure, keep the last good);
- :mod:`.app`: the wiring; :mod:`.view3d`: the 3D scene; :mod:`.controls`: the player
  and the sliders; :mod:`.plots`: the numbers; :mod:`.edits`: Save's rewrite of the
  text; :mod:`.disk`: reading the file and Save's checks; :mod:`.watch`: reloading when
  the file changes on disk;
- :mod:`.gate`: only the printed address's page is answered (token, Host, Origin);
  :mod:`.serving`: viser's server behind it, and the check of what a page sends;
- :mod:`.stage`: a scenario's perception loop played live (:mod:`.liveview` draws what
  the camera sees and the confidence).

docs/studio.md says how to use it.
"""

from __future__ import annotations

import sys
import threading
from typing import Any

__all__ = ["serve"]


def serve(path: str, *, robot: str | None = None, host: str = "127.0.0.1", port: int = 8080,
          compare: str | None = None, stop: threading.Event | None = None,
          package_dirs: tuple[str, ...] = (), fit: bool = False,
          perception: str = "geometric", track: str | None = None) -> int:
    """Run the studio of ``path`` until interrupted (or ``stop`` is set); the exit status
    (130 after Ctrl-C, as every aouc command). ``fit``: build as ``aouc compile --fit``
    does; ``track``: a servo mode, the arm as its servos track the motion drawn
    ghosted. A scenario (``.toml``) plays the perception loop live (:mod:`.stage`) with
    ``perception``. The address printed carries the per-run token without which the
    studio answers nothing.

    Raises:
        AouError: the file (or ``compare``) does not build, or the robot cannot be drawn.
        ImportError: the ``studio`` extra is not installed.
    """
    import viser  # noqa: F401 - the extra, before any work
    import watchfiles  # noqa: F401
    import yourdfpy  # noqa: F401

    from .app import LOCAL, Studio

    if host not in (LOCAL, "localhost"):
        print(f"aouc: warning: the studio binds {host}: anyone who can reach this machine "
              "can see the page and save into the file", file=sys.stderr)
    studio: Any
    if path.endswith(".toml"):
        from .stage import Stage

        studio = Stage(path, robot=robot, perception=perception, host=host,
                       port=port).start()
    else:
        studio = Studio(path, robot=robot, host=host, port=port, compare=compare,
                        package_dirs=package_dirs, fit=fit, track=track).start()
    if studio.port != port:
        print(f"aouc: port {port} is taken: serving on {studio.port} (--port chooses)",
              file=sys.stderr)
    try:
        print(f"aouc studio: {studio.url} (Ctrl-C stops)", file=sys.stderr, flush=True)
        done = stop or threading.Event()
        # Woken twice a second: the OS may hand Ctrl-C to another of the studio's
        # threads, and a wait with no end would then never see it.
        while not done.wait(0.5):
            pass
    except KeyboardInterrupt:  # the way to stop it
        print("aouc studio: stopped", file=sys.stderr)
        return 130
    finally:
        studio.close()
    return 0
