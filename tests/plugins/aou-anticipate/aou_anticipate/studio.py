"""The ``studio`` part: the colour an anticipation is drawn in (the hand's path, the
timeline's bands), and the slider of its distance, over the range the kind accepts."""

from __future__ import annotations

from .descriptors import DISTANCE
from .kind import MAX_DISTANCE

__all__ = ["colour", "ranges"]

#: An amber, apart from the built-in kinds' colours. RGB 0-255.
colour = (212, 160, 23)
#: The distance slider: 5 mm to the largest anticipation, by the millimetre (low, high,
#: step). The count takes the studio's slider of counts.
ranges = {DISTANCE.name: (0.005, MAX_DISTANCE, 0.001)}
