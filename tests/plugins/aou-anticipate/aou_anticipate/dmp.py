"""The ``dmp`` part: an anticipation in a DMP folder is a move, a Cartesian DMP of the
hand from rest to rest fitted to the episode, like a retreat's."""

from __future__ import annotations

__all__ = ["intensity", "parameters", "scaling", "shape"]

#: A Cartesian DMP of the hand's pose, fitted to the episode.
shape = "move"
#: Which DMP parameter controls each of the kind's descriptors, by episode key
#: (``""``: the count).
parameters = {
    "distance": "start_y/goal_y and forcing weights (amplitude scaling)",
    "": "the parts (fixed)",
}
#: A rollout to a goal `s` times as far draws back `s` times as far.
scaling = {"distance": "space"}
#: An intensity changes no anticipation without a re-plan.
intensity: frozenset[str] = frozenset()
