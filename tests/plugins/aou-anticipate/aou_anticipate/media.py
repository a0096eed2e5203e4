"""The ``media`` part: how anticipations are shaded and labelled in plots."""

from __future__ import annotations

__all__ = ["colour", "label"]

#: The studio's amber, as ``#rrggbb``.
colour = "#d4a017"
#: The word shown on its episodes.
label = "anticipation"
