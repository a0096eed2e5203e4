"""The contract of a primitive kind: what a new kind must provide, checked by Python when
the kind is made and by mypy when it is used; the layout and the compiler rely on it."""

from __future__ import annotations

import re

import pytest

from aou_dsl.lang.ir import Node
from aou_dsl.lang.primitives import KINDS, Kind, Timing
from aou_dsl.lang.primitives.pause import PauseKind
from tests.conftest import ROOT


def test_every_kind_states_its_timing_as_the_enum():
    """Each registered kind is a Kind with a Timing; the compiler dispatches on it."""
    assert set(KINDS) == {"approach", "pause", "retreat", "gaze", "tilt", "shiver"}
    for kind in KINDS.values():
        assert isinstance(kind, Kind) and isinstance(kind.timing, Timing)
    assert KINDS["pause"].timing is Timing.HOLD
    assert KINDS["shiver"].timing is Timing.OSCILLATION


def test_a_kind_without_its_class_attributes_is_refused_when_made():
    """A subclass that does not say its name, node, usage or C-V evidence is a TypeError
    at its definition, naming what is missing."""
    with pytest.raises(TypeError, match="evidence"):
        class Wave(Kind):  # noqa: F841
            name, node, usage = "wave", Node, "wave"


def test_a_kind_without_its_methods_cannot_be_instantiated():
    """A kind that leaves an abstract method out (here: how it lays an episode out)
    cannot be instantiated."""
    class Half(PauseKind):
        pass

    Half()  # a complete kind instantiates
    namespace = {k: v for k, v in vars(PauseKind).items() if k != "episode"}
    Broken = type("Broken", (Kind,), namespace)
    with pytest.raises(TypeError, match="episode"):
        Broken()


#: The one ``Any`` left: toppra ships no types, and its solver class is subclassed.
UNTYPED_LIBRARY = {"compiler/topp.py": 1}


@pytest.mark.parametrize("module", ["lang/layout.py", *sorted(
    str(p.relative_to(ROOT / "aou_dsl")) for p in (ROOT / "aou_dsl" / "compiler").glob("*.py"))])
def test_layout_and_compiler_need_no_escape_from_the_types(module):
    """No ``type: ignore`` in the layout or the compiler, and no ``Any`` but where an
    untyped library's class is subclassed: the kinds' contract types the rest."""
    text = (ROOT / "aou_dsl" / module).read_text()
    code = re.sub(r'"""[\s\S]*?"""|#.*', "", text.replace("# type: ignore", "TYPE-IGNORE"))
    assert "TYPE-IGNORE" not in code, module
    anys = len(re.findall(r"\bAny\b", code)) - ("from typing import Any" in code)
    assert anys == UNTYPED_LIBRARY.get(module, 0), module
