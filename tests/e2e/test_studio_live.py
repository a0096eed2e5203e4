"""``aouc studio SCENARIO.toml``: the perception loop played live, its page and its gate.

The view is checked against the geometric model's own ray tests; the stage is driven the
way a page drives it, through its websocket with viser's own messages, so the gate and
the check of each value are on the path (a page in a real browser: the slow variant in
tests/e2e/test_studio_browser.py).
"""

from __future__ import annotations

import asyncio
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")

from aou_dsl.live.loop import HYSTERESIS
from aou_dsl.live.regulator import Regulator
from aou_dsl.live.world import Box, Scene, tag_points, visible_fraction
from aou_dsl.studio import liveview
from tests.e2e.conftest import wait_for
from tests.integration.test_studio_gate import _open, _update, _uuid

ROOT = str(Path(__file__).resolve().parents[2])
OCCLUDER = os.path.join(ROOT, "examples", "scenarios", "occluder.toml")
#: Where the card of the shipped scenario covers the tag, and where it leaves it clear.
OVER, AWAY = 0.0, 0.16
ORDER = ["confident", "curious", "hesitant", "fearful", "inactive"]


def _inside(poly: list[tuple[float, float]], x: float, y: float) -> bool:
    """Whether (x, y) is inside the polygon (even-odd rule)."""
    inside = False
    for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1], strict=True):
        if (y0 > y) != (y1 > y) and x < x0 + (y - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
    return inside


def _polygons(svg: str) -> dict[str, list[tuple[float, float]]]:
    out = {}
    for pts, part in re.findall(r'<polygon points="([^"]+)"[^>]*?data-part="([^"]+)"', svg):
        out[part] = [tuple(map(float, p.split(","))) for p in pts.split()]
    return out


@pytest.mark.parametrize(("y", "covers"), [(0.16, False), (0.07, False), (0.02, True),
                                           (0.0, True)])
def test_the_view_draws_the_card_over_the_tag_as_the_ray_tests_find_it(y, covers):
    """The tag's centre is drawn under the card exactly when the model's ray test from
    the camera to it hits the card."""
    card = Box((0.45, y, 0.06), (0.005, 0.03, 0.06), "card")
    scene = Scene(occluders=(card,))
    svg = liveview.camera_svg(scene, visible_fraction(scene, tag_points(scene, cells=8)))
    polys = _polygons(svg)
    tag = np.asarray(polys["tag"])
    cx, cy = tag.mean(axis=0)
    centre = tag_points(scene, cells=1)[4:]
    hidden = visible_fraction(scene, centre) == 0.0
    assert ("card" in polys and _inside(polys["card"], cx, cy)) == hidden, (y, hidden)
    assert hidden == covers  # the sweep has both cases


def test_the_view_darkens_with_the_light_and_leaves_out_what_is_behind_the_camera():
    behind = Box((0.0, 0.0, 0.15), (0.02, 0.02, 0.02), "behind")
    lit = liveview.camera_svg(Scene(occluders=(behind,)))
    dark = liveview.camera_svg(Scene(light=0.1, occluders=(behind,)))
    assert 'data-part="tag" ' not in lit and "behind" not in lit
    assert 'fill="rgb(255,255,255)" data-part="tag"' in lit
    assert 'fill="rgb(26,26,26)" data-part="tag"' in dark


#: The shipped scenario's scene, its card away from the tag, and no timeline: only the
#: page moves it.
STILL = """title = "A card the page moves"
duration = 60.0

[scene]
target = [0.6, 0.0, 0.04]
camera = [0.2, 0.0, 0.15]

[[occluder]]
name = "card"
center = [0.45, 0.16, 0.06]
size = [0.01, 0.06, 0.12]
"""


@pytest.fixture(scope="module")
def reg() -> Regulator:
    """One regulator whose plans the stages share (each stage starts it afresh)."""
    return Regulator("panda", intensity_step=0.5, hysteresis=HYSTERESIS)


@pytest.fixture(scope="module")
def still(tmp_path_factory):
    path = tmp_path_factory.mktemp("stage") / "still.toml"
    path.write_text(STILL)
    return str(path)


@pytest.fixture(scope="module")
def stage(reg, still):
    from aou_dsl.studio.stage import Stage

    s = Stage(still, port=0, regulator=reg).start()
    yield s
    s.close()


def _send(stage, handle, value) -> tuple[str, object]:
    q = f"?token={stage.gate.token}"
    return asyncio.run(_open(stage.port, query=q, send=[_update(_uuid(handle), {"value": value})],
                             quiet=0.5))


def test_a_page_moving_the_card_over_the_tag_makes_the_arm_hesitant_and_back(stage):
    """The card's slider, moved by a page through the gate: the state the page shows
    walks from confident towards hesitant while the card covers the tag, and back to
    confident when it leaves; the arm follows a motion the loop sent at every step."""
    y = stage.sliders["card"][1]
    wait_for(lambda: stage.drawn > 2 and 'data-state="confident"' in stage.state.content)
    seen = len(stage.ticks)
    assert _send(stage, y, OVER)[0] == "open"
    wait_for(lambda: 'data-state="hesitant"' in stage.state.content)
    assert stage.scene_at(0.0).occluders[0].center[1] == OVER
    states = [tk.state for tk in list(stage.ticks)[-(len(stage.ticks) - seen):]]
    walked = [s for k, s in enumerate(states) if k == 0 or s != states[k - 1]]
    assert walked[0] == "confident" and walked[-1] == "hesitant"
    assert [ORDER.index(s) for s in walked] == sorted(ORDER.index(s) for s in walked)
    assert 'data-visible="0.000"' in stage.view.content  # the view shows the tag hidden
    assert _send(stage, y, AWAY)[0] == "open"
    wait_for(lambda: 'data-state="confident"' in stage.state.content)
    assert 'data-state="confident"' in stage.plot.content
    assert 'data-state="hesitant"' in stage.plot.content
    assert all(s.kind != "held" for s in stage.loop.switches)


def test_a_page_dimming_the_light_makes_the_arm_fearful_then_inactive_and_back(stage):
    """The light's slider, moved by a page: darkness walks the state past hesitant to
    fearful or inactive, as the mapping says; the light back brings confident back."""
    wait_for(lambda: 'data-state="confident"' in stage.state.content)
    assert _send(stage, stage.light, 0.0)[0] == "open"
    wait_for(lambda: re.search(r'data-state="(fearful|inactive)"', stage.state.content))
    assert stage.scene_at(0.0).light == 0.0
    assert 'fill="rgb(0,0,0)" data-part="tag"' in stage.view.content  # a dark view
    assert _send(stage, stage.light, 1.0)[0] == "open"
    wait_for(lambda: 'data-state="confident"' in stage.state.content)


def test_a_page_moving_the_target_behind_the_card_makes_the_arm_hesitant(stage):
    """The target's sliders: moved behind the card (which stays where it is), the tag is
    hidden and the arm grows hesitant; moved back, confident. The 3D target follows."""
    x, y, z = stage.sliders["target"]
    wait_for(lambda: 'data-state="confident"' in stage.state.content)
    assert _send(stage, y, 0.25)[0] == "open"
    wait_for(lambda: 'data-state="hesitant"' in stage.state.content)
    assert stage.scene_at(0.0).target == pytest.approx((0.6, 0.25, 0.04))
    assert stage.scene_at(0.0).occluders[0].center == pytest.approx((0.45, AWAY, 0.06))
    wait_for(lambda: tuple(stage.target.position) == pytest.approx((0.6, 0.25, 0.04)))
    assert _send(stage, y, 0.0)[0] == "open"
    wait_for(lambda: 'data-state="confident"' in stage.state.content)


def test_the_gate_covers_the_scenes_controls(stage):
    """Without the token a page cannot move the card; a value past the slider's range is
    clamped to it before the loop sees it."""
    x, y, z = stage.sliders["card"]
    before = stage.scene_at(0.0).occluders[0].center
    raw = [_update(_uuid(y), {"value": 0.3})]
    assert asyncio.run(_open(stage.port, send=raw, quiet=0.3)) == ("refused", 403)
    assert asyncio.run(_open(stage.port, query="?token=wrong", send=raw,
                             quiet=0.3)) == ("refused", 403)
    time.sleep(0.5)
    assert stage.scene_at(0.0).occluders[0].center == before
    assert _send(stage, z, 1e9)[0] == "open"
    wait_for(lambda: stage.scene_at(0.0).occluders[0].center[2] == z.max)
    assert "range" in stage.notice.content
    assert _send(stage, z, "high")[0] == "open"  # not a number: not applied
    assert stage.scene_at(0.0).occluders[0].center[2] == z.max
    assert _send(stage, stage.light, float("nan"))[0] == "open"
    assert stage._light is None or np.isfinite(stage._light)
    _send(stage, z, 0.06)


def test_aouc_studio_refuses_shaping_flags_with_a_scenario(tmp_path):
    for extra in (["--fit"], ["--compare", "x.aou"]):
        out = subprocess.run([sys.executable, "-m", "aou_dsl", "studio", OCCLUDER, *extra],
                             capture_output=True, text=True, timeout=120)
        assert out.returncode == 2 and "scenario" in out.stderr, out.stderr
    out = subprocess.run([sys.executable, "-m", "aou_dsl", "studio",
                          os.path.join(ROOT, "behaviours", "hesitant.aou"), "--perception",
                          "camera"], capture_output=True, text=True, timeout=120)
    assert out.returncode == 2 and "scenario" in out.stderr, out.stderr


def test_what_a_page_sends_the_scene_controls_breaks_no_page_nor_the_loop(stage, capfd):
    """A fuzz of the scene's controls as tests/integration/test_studio_fuzz.py sends the studio's:
    values of every wrong type and size, properties a page must not change, other kinds
    of message and bytes that are none. Every next page gets the scene, every slider
    holds a value in its range, the scene the perception sees stays finite and the loop
    goes on ticking, and nothing says an internal error."""
    import math
    import random

    import msgspec

    from tests.integration.test_studio_fuzz import KEYS, KINDS, NUMBERS, OTHERS

    rng = random.Random(5)
    handles = [stage.light, *(h for hs in stage.sliders.values() for h in hs)]
    uuids = [_uuid(h) for h in handles] + ["no-such-control", "", None, 5]
    sent = []
    for _ in range(40):
        roll = rng.random()
        if roll < 0.75:
            keys = rng.sample(KEYS, rng.choice((1, 1, 2)))
            msg = {"type": "GuiUpdateMessage", "uuid": rng.choice(uuids),
                   "updates": {k: rng.choice(NUMBERS + OTHERS) for k in keys}}
        elif roll < 0.9:
            msg = {"type": rng.choice(KINDS), "uuid": rng.choice(uuids), "values": {}}
        else:
            sent.append(rng.choice([b"", b"\xc1", b"not msgpack"]))
            continue
        try:
            sent.append(msgspec.msgpack.encode(msg))
        except (OverflowError, msgspec.EncodeError):
            continue
    port, q = stage.port, f"?token={stage.gate.token}"
    for i in range(0, len(sent), 20):
        state, _ = asyncio.run(_open(port, query=q, send=sent[i:i + 20], quiet=0.3))
        assert state in ("open", "closed")
        state, got = asyncio.run(_open(port, query=q, quiet=0.5))
        assert state == "open" and got > 10_000, (i, state, got)
    before = len(stage.ticks) and stage.ticks[-1].t
    wait_for(lambda: stage.ticks[-1].t > before + 0.5)  # the loop ticks on
    for h in handles:
        assert h.min <= h.value <= h.max and math.isfinite(h.value), h.label
    s = stage.scene_at(stage.ticks[-1].t)
    assert all(math.isfinite(x) for x in (*s.target, s.light,
                                          *(c for b in s.occluders for c in b.center)))
    err = capfd.readouterr().err
    assert "internal error" not in err and "Traceback" not in err, err[-2000:]
    assert "internal error" not in stage.notice.content
    assert stage.inbox.refused > 0
    # the page's own values again, for the tests after this one
    for name, centre in (("card", (0.45, AWAY, 0.06)), ("target", (0.6, 0.0, 0.04))):
        stage.place(name, centre)
    stage.set_light(1.0)


def test_the_rendered_camera_plays_live_and_its_frame_is_shown(reg, still, stage):
    """With the rendered camera the page shows its last frame (a PNG of 320 x 240), and
    the card over the tag makes the arm hesitant as with the model."""
    pytest.importorskip("pupil_apriltags", reason="the perception extra is missing")
    import base64
    import io

    from PIL import Image

    from aou_dsl.studio.stage import Stage

    stage.close()  # one loop at a time on the shared regulator (this test runs last)
    s = Stage(still, port=0, regulator=reg, perception="camera").start()
    try:
        wait_for(lambda: s.drawn > 2 and 'data-state="confident"' in s.state.content)
        src = re.search(r'<img id="aou-camera" src="data:image/png;base64,([^"]+)"',
                        s.view.content)
        assert src is not None
        img = Image.open(io.BytesIO(base64.b64decode(src.group(1))))
        assert img.size == (320, 240) and np.asarray(img).std() > 10  # a picture
        s.place("card", (0.45, OVER, 0.06))
        wait_for(lambda: 'data-state="hesitant"' in s.state.content)
        assert "internal error" not in getattr(s.notice, "content", "")
    finally:
        s.close()
