"""aou-anticipate: the ``anticipate`` primitive for aou, as a plugin.

``anticipate DIST [a=ACC] [xN]`` draws the end-effector back from the goal by ``DIST``
(5 to 50 mm) along the line of sight, rest to rest at peak acceleration ``a``, directly
before an approach: the wind-up of an animator's anticipation. aou finds this package
through its entry point (group ``aou.kinds``, name ``anticipate``, object :data:`plugin`)
and reads one part per layer from :data:`plugin`'s attributes.
"""

from __future__ import annotations

from types import SimpleNamespace

from . import dmp, editor, media, studio
from .descriptors import DESCRIPTORS
from .kind import NAME, Anticipate, AnticipateKind
from .measure import Recognise

__all__ = ["NAME", "Anticipate", "AnticipateKind", "plugin"]

#: The plugin: one part per layer it takes part in (the names of ``aou_dsl.core.plugins.
#: LAYERS``).
plugin = SimpleNamespace(
    kind=AnticipateKind(),
    descriptors=DESCRIPTORS,
    measure=Recognise(),
    dmp=dmp,
    editor=editor,
    studio=studio,
    media=media,
)
