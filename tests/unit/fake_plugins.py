"""Installing a made-up primitive kind plugin for one test, the way pip would: a
``*.dist-info`` folder whose ``entry_points.txt`` names an object under ``aou.kinds``,
and the module it points at, both in a folder put first on ``sys.path``.

``LURCH`` is a whole kind written against aou's public contract only (a move straight
away from the goal, timed like a retreat, feeding the retreat extent of the C-V
inference, with two descriptors of its own); the tests change it to make plugins that
clash, break or give malformed parts.
"""

from __future__ import annotations

import sys
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest

from aou_dsl.core import plugins

#: A plugin module: the kind ``lurch`` and its descriptors.
LURCH = '''
from dataclasses import dataclass

from aou_dsl.core.units import Dim
from aou_dsl.lang.descriptors import Aggregate, Descriptor
from aou_dsl.lang.ir import Node
from aou_dsl.lang.primitives import Kind, Timing
from aou_dsl.lang.primitives.kind import Key, fmt, move, repeat
from aou_dsl.lang.timeline import Pose

NAME = "lurch"


@dataclass(frozen=True, kw_only=True, slots=True)
class Lurch(Node):
    kind: str = NAME
    length: float
    a: float
    count: int = 1


class LurchKind(Kind):
    name = NAME
    node = Lurch
    usage = "lurch LENGTH [a=ACC] [xN]"
    keys = {"a": Key(Dim.ACCEL, "m/s^2", "acceleration")}
    timing = Timing.OPTIMAL
    translation = True
    evidence = {"extent": ("distance", "sum")}

    def read(self, r):
        q = r.quantity("a distance")
        d = r.si(q, Dim.LENGTH, "lurch distance")
        a = r.key("a")
        if r.done() and d is not None:
            return Lurch(span=r.st.span, length=d, a=a or 0.5, count=r.count)
        return None

    def episode(self, node, pose, arg=None):
        end = Pose(pose.d + node.length, pose.h, pose.v, pose.roll)
        return move(NAME, node.span, pose, end, node.a, 0.25)

    def values(self, node):
        return {"distance": abs(node.length), "peak_acceleration": node.a}

    def episode_values(self, ep):
        return {"distance": ep.path_length, "peak_acceleration": ep.a}

    def format(self, node):
        return f"lurch {fmt(node.length)}m a={fmt(node.a)}{repeat(node.count)}"


kind = LurchKind()
descriptors = (
    Descriptor("lurch_distance", "m", NAME, "distance", Aggregate.MEDIAN, "length",
               abs_tol=1e-3),
    Descriptor("lurch_count", "", NAME, "", Aggregate.COUNT, "count"),
)
'''


def install(folder: Path, monkeypatch: pytest.MonkeyPatch, *, entry: str, module: str,
            source: str, dist: str = "aou-fake", version: str = "0.1") -> None:
    """Install distribution ``dist`` whose ``aou.kinds`` entry point ``entry`` is the
    module ``module`` (of text ``source``): put on ``sys.path`` for this test only."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{module}.py").write_text(textwrap.dedent(source), encoding="utf-8")
    info = folder / f"{dist.replace('-', '_')}-{version}.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\n"
                                   f"Version: {version}\n", encoding="utf-8")
    (info / "entry_points.txt").write_text(f"[aou.kinds]\n{entry} = {module}\n",
                                           encoding="utf-8")
    monkeypatch.syspath_prepend(str(folder))
    monkeypatch.delenv("AOU_NO_PLUGINS", raising=False)
    plugins.loaded.cache_clear()  # type: ignore[attr-defined]


@pytest.fixture
def fresh_plugins() -> Iterator[None]:
    """Forget the loaded plugins (and the modules the test installed) after the test."""
    before = set(sys.modules)
    yield
    for name in set(sys.modules) - before:
        if name.startswith("aou_fake_"):
            del sys.modules[name]
    plugins.loaded.cache_clear()  # type: ignore[attr-defined]
