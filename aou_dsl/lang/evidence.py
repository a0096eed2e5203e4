"""The evidence channels of the C-V inference, and the check of a kind's evidence table.

Each primitive kind says, in its ``evidence`` table, which channels its episodes feed
(channel -> (episode value key, ``"sum"`` or ``"max"``)): the values of its episodes
are added up or the largest is kept, per channel, and :mod:`.cv` turns each channel into
one term of the (C, V) point. A kind from a plugin feeds them the same way; its table is
checked here when it loads (a table naming anything else keeps the plugin out, K801).
Kept apart from :mod:`.cv` so the kinds' registry can check a table without importing
the inference. Pure Python.
"""

from __future__ import annotations

from collections.abc import Mapping

__all__ = ["CHANNELS", "evidence_problem"]

#: The evidence channels a kind's ``evidence`` table may feed, each with what it pulls:
#: C up (drive), C down (extent, vigour) or V up (stillness, exploration, tremor), and
#: the unit of the values that feed it. A plugin kind's episodes feed the channels its
#: table names, like the built-ins'.
#: The names are :class:`.cv.Composition`'s fields.
CHANNELS: dict[str, str] = {
    "drive": "C up; peak acceleration towards the goal [m/s^2]",
    "extent": "C down; distance moved away from the goal [m]",
    "vigour": "C down; peak acceleration away from the goal [m/s^2]",
    "stillness": "V up; time held still [s]",
    "exploration": "V up; angle turned while looking [deg]",
    "tremor": "V up; amplitude of a fast oscillation [deg]",
}
#: How the values of several episodes feed one channel.
_HOW = ("sum", "max")


def evidence_problem(evidence: object) -> str | None:
    """What is wrong with a kind's ``evidence`` table (channel -> (episode value key,
    ``"sum"`` or ``"max"``)), in words, or None when it is well formed."""
    if not isinstance(evidence, Mapping):
        return "its `evidence` is not a mapping of channel to (value key, sum/max)"
    for channel, how in evidence.items():
        if channel not in CHANNELS:
            return (f"its evidence names the channel `{channel}`; the channels are "
                    f"{', '.join(CHANNELS)}")
        if not (isinstance(how, tuple) and len(how) == 2 and isinstance(how[0], str)
                and how[1] in _HOW):
            return (f"its evidence for `{channel}` is not (value key, \"sum\" or \"max\"): "
                    f"{how!r}")
    return None
