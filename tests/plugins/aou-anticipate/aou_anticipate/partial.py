"""The plugin with a part left out, for the tests of what aou says then: each object
here can be an entry point's object in place of :data:`aou_anticipate.plugin`."""

from __future__ import annotations

from types import SimpleNamespace

from . import plugin

__all__ = ["nothing", "without", "without_dmp", "without_measure", "without_studio"]


def without(*layers: str) -> SimpleNamespace:
    """The plugin without the parts of ``layers``."""
    return SimpleNamespace(**{k: v for k, v in vars(plugin).items() if k not in layers})


without_dmp = without("dmp")
without_measure = without("measure")
without_studio = without("studio")
#: No kind part: not a kind plugin at all (aou reports it and goes on without it).
nothing = without("kind")
