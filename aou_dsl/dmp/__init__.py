"""Behaviours as Dynamic Movement Primitives: export, roll out to a new goal and tempo, and
check that the motion still means what it meant.

A compiled trajectory becomes a sequence of parts (:func:`to_dmp`): one
``movement_primitives`` ``CartesianDMP`` of the hand's pose per rest-to-rest motion
episode, a hold per pause, and a shiver as an oscillation of the roll. :func:`write_dmp`
writes the sequence as a folder of the library's part files beside a manifest;
:func:`read_dmp` reads it back as untrusted input (:mod:`.reader`); :func:`roll` rolls it out to a
new goal, time scale and intensity and :func:`solve` makes joint motion of it, checked
and measured like a compile (docs/dmp.md). Needs the ``dmp`` extra.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from .export import DmpSequence

__all__ = ["EXTRA_HINT", "read_dmp", "roll", "solve", "to_dmp", "write_dmp"]

#: What to say when ``movement_primitives`` (or a dependency it leaves undeclared) is missing.
EXTRA_HINT = ("pip install '.[dmp]' in aou's folder (the one with pyproject.toml)")


def to_dmp(trajectory: Any, **options: Any) -> DmpSequence:
    """:func:`aou_dsl.dmp.export.to_dmp`."""
    from .export import to_dmp as run

    return run(trajectory, **options)


def write_dmp(path: str, sequence: DmpSequence, *, inputs: Any = ()) -> None:
    """:func:`aou_dsl.dmp.manifest.write_dmp`."""
    from .manifest import write_dmp as run

    run(path, sequence, inputs=inputs)


def read_dmp(path: str) -> DmpSequence:
    """:func:`aou_dsl.dmp.manifest.read_dmp`."""
    from .manifest import read_dmp as run

    return run(path)


def roll(sequence: DmpSequence, **options: Any):
    """:func:`aou_dsl.dmp.rollout.roll`."""
    from .rollout import roll as run

    return run(sequence, **options)


def solve(sequence: DmpSequence, **options: Any):
    """:func:`aou_dsl.dmp.solve.solve`."""
    from .solve import solve as run

    return run(sequence, **options)
