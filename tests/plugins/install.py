"""Installing the test plugin without pip: what ``pip install tests/plugins/aou-anticipate``
would leave for Python to find, made in a temporary folder.

A distribution is found by its ``*.dist-info`` folder on the import path: its
``METADATA`` names it and its ``entry_points.txt`` lists the entry points aou reads
(group ``aou.kinds``). :func:`installed` writes one (pointing at the real package's
``plugin`` object, or at another object of it: a plugin with a part missing), puts it and
the package's folder on ``sys.path`` for tests in this process, and gives the
``PYTHONPATH`` that does the same for an ``aouc`` subprocess. On leaving, both are gone
and aou's plugin cache forgets them: the next test sees aou as installed, without it.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

__all__ = ["PACKAGE", "ROOT", "Installed", "clear_caches", "for_commands", "installed",
           "without_plugins", "write_dist"]

ROOT = Path(__file__).resolve().parents[2]
#: The plugin's project folder (its pyproject.toml and the `aou_anticipate` package).
PACKAGE = Path(__file__).resolve().parent / "aou-anticipate"


@dataclass(frozen=True)
class Installed:
    """Where the plugin was installed and the environment an ``aouc`` subprocess needs
    to see it."""

    site: Path
    env: dict[str, str]


def clear_caches() -> None:
    """Forget what aou loaded of the installed plugins (in this process)."""
    from aou_dsl.core import plugins

    plugins.loaded.cache_clear()


def write_dist(site: Path, entry: str = "aou_anticipate:plugin") -> Path:
    """A ``dist-info`` folder in ``site`` for the distribution ``aou-anticipate`` whose
    ``anticipate`` entry point of group ``aou.kinds`` is ``entry``."""
    info = site / "aou_anticipate-0.1.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: aou-anticipate\nVersion: 0.1\n"
        "Summary: The anticipate primitive for aou\n", encoding="utf-8")
    (info / "entry_points.txt").write_text(f"[aou.kinds]\nanticipate = {entry}\n",
                                           encoding="utf-8")
    return info


def _env(paths: list[str]) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "AOU_NO_PLUGINS"}
    old = [p for p in env.get("PYTHONPATH", "").split(os.pathsep) if p]
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *paths, *old])
    return env


def for_commands(tmp: Path, entry: str = "aou_anticipate:plugin") -> Installed:
    """The plugin installed in ``tmp`` for ``aouc`` subprocesses only (this process's
    import path is left as it is): run them with the returned ``env``."""
    site = tmp / "site"
    write_dist(site, entry)
    return Installed(site, _env([str(site), str(PACKAGE)]))


@contextmanager
def installed(tmp: Path, entry: str = "aou_anticipate:plugin") -> Iterator[Installed]:
    """The plugin installed (its entry point pointing at ``entry``) while inside, for
    this process and for ``aouc`` subprocesses."""
    inst = for_commands(tmp, entry)
    paths = [str(inst.site), str(PACKAGE)]
    sys.path[:0] = paths
    clear_caches()
    try:
        yield inst
    finally:
        for p in paths:
            sys.path.remove(p)
        clear_caches()


def without_plugins() -> dict[str, str]:
    """The environment of an ``aouc`` subprocess that sees no plugin (none installed)."""
    return _env([])


def wind_up(draw: str = "10mm", a: float = 0.4, approach_a: float = 0.01) -> str:
    """The plugin's example: a sequence whose anticipation draws back ``draw`` at peak
    acceleration ``a`` [m/s^2] right before an approach at ``approach_a``."""
    return (f"behaviour wind_up\nrobot panda\nstart 0.30m\nstandoff 0.10m\nsequence {{\n"
            f"  pause 1s\n  anticipate {draw} a={a:g}\n  approach 0.1m a={approach_a:g}\n"
            f"  pause 1s\n  approach a={approach_a:g}\n}}\n")
