"""A fuzz of what a page can send the studio: messages of every kind viser decodes, for
every control of the page, with values of the wrong type, huge, NaN, infinite,
negative, with property names a control has but a page must not change, for controls
that do not exist, and bytes that are no message at all. Written from the promise, not
from the code: whatever a page sends, every page that connects next gets the whole
scene, the studio says no internal error, every control keeps a value it could hold,
and the file is untouched (no message here is a valid click of Save). Bytes viser
cannot decode as a message close the connection that sent them, and only that one.

The default run sends a bounded sample; ``-m slow`` a larger one.
"""

from __future__ import annotations

import asyncio
import logging
import math
import os
import random
import shutil
import traceback
from pathlib import Path

import pytest

pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")

import msgspec

from tests.integration.test_studio_gate import _open, _wait_idle

ROOT = str(Path(__file__).resolve().parents[2])

NUMBERS = [0, 1, -1, -5, 3, 2.5, 1e-320, -0.0, 0.5, 7, 11, 1e6, -1e6, 1e20, -1e20, 1e308,
           -1e308, math.nan, math.inf, -math.inf, 2 ** 63, -(2 ** 63), 2 ** 64 - 1]
OTHERS = [None, True, False, "", "5", "nan", "1e400", "x" * 2000, [], [1, 2], {},
          {"value": 1}, b"\x00\xff", "0.25", "1", "2", "9"]
KEYS = ["value", "min", "max", "step", "label", "visible", "disabled", "options",
        "hint", "order", "_impl", "__class__", "precision", ""]
KINDS = ["ShareUrlRequest", "ShareUrlDisconnect", "GuiButtonHoldMessage",
         "GuiFormSubmitMessage", "FileTransferStartUpload", "FileTransferPart",
         "CommandTriggerMessage", "ScenePointerMessage", "NoSuchMessage"]


def _camera(rng: random.Random) -> dict:
    n = lambda: rng.choice(NUMBERS)  # noqa: E731
    return {"type": "ViewerCameraMessage", "wxyz": rng.choice(
                [[n() for _ in range(rng.choice((3, 4)))], None, 1.0, "wxyz"]),
            "position": [n(), n(), n()], "fov": n(), "near": n(), "far": n(),
            "image_height": rng.choice((480, -1, 2 ** 40, 1.5)),
            "image_width": rng.choice((640, 0, 2 ** 63)), "look_at": [n(), n(), n()],
            "up_direction": [n(), n(), n()]}


def messages(studio, n: int, seed: int) -> list[bytes]:
    """``n`` messages a page could send, at random (``seed``)."""
    rng = random.Random(seed)
    controls = {name: h._impl.uuid for name, h in studio.sliders.handles.items()}
    player = studio.player
    controls.update(time=player.time._impl.uuid, speed=player.speed._impl.uuid,
                    loop=player.loop._impl.uuid, pause=player.button._impl.uuid)
    save, reload = studio.save_button._impl.uuid, studio.reload_button._impl.uuid
    uuids = [*controls.values(), save, reload, "no-such-control", "", None, 5, ["x"],
             {"a": 1}]
    out = []
    for _ in range(n):
        roll = rng.random()
        if roll < 0.6:
            uuid = rng.choice(uuids)
            keys = rng.sample(KEYS, rng.choice((1, 1, 1, 2)))
            updates = {k: rng.choice(NUMBERS + OTHERS) for k in keys}
            if uuid == save and updates.get("value") is True:  # no valid click of Save
                updates["value"] = 1
            if uuid == reload and updates.get("value") is True:
                updates["value"] = "yes"
            msg: object = {"type": "GuiUpdateMessage", "uuid": uuid, "updates": updates}
            if rng.random() < 0.05:
                msg = {"type": "GuiUpdateMessage", "uuid": uuid, "updates": rng.choice(
                    [None, 5, "value", [["value", 1]]])}
        elif roll < 0.75:
            msg = _camera(rng)
        elif roll < 0.9:
            msg = {"type": rng.choice(KINDS), "uuid": rng.choice(uuids),
                   "frequency": rng.choice(NUMBERS), "values": {}, "source_component_uuid":
                   rng.choice(uuids), "transfer_uuid": "t", "filename": "../../x",
                   "mime_type": "text/plain", "part_count": rng.choice(NUMBERS),
                   "size_bytes": rng.choice(NUMBERS), "content": b"x"}
        else:
            out.append(rng.choice([b"", b"\xc1", b"not msgpack", msgspec.msgpack.encode([1]),
                                   msgspec.msgpack.encode({"uuid": "x"})]))
            continue
        try:
            out.append(msgspec.msgpack.encode(msg))
        except (OverflowError, msgspec.EncodeError):  # not sendable: no page sends it
            continue
    return out


@pytest.fixture(scope="module")
def studio(tmp_path_factory):
    from aou_dsl.studio.app import Studio

    folder = tmp_path_factory.mktemp("fuzz")
    path = folder / "h.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    s = Studio(str(path), port=0).start()
    s.file = path
    s.original = path.read_bytes()
    yield s
    s.close()


def _fuzz(studio, capfd, caplog, n: int, batch: int, seed: int) -> None:
    port, q = studio.port, f"?token={studio.gate.token}"
    sent = messages(studio, n, seed)
    caplog.set_level(logging.ERROR)
    for i in range(0, len(sent), batch):
        state, _ = asyncio.run(_open(port, query=q, send=sent[i:i + batch], quiet=0.3))
        assert state in ("open", "closed")  # bytes that are no message close the sender
        state, got = asyncio.run(_open(port, query=q, quiet=1.0))  # the next page
        assert state == "open" and got > 10_000, (i, state, got)
    _wait_idle(studio)
    err = capfd.readouterr().err
    assert "internal error" not in err and "Error" not in err, err[-3000:]
    for r in caplog.records:  # only a sender of bytes viser cannot decode was closed
        assert r.exc_info and "in deserialize" in "".join(
            traceback.format_exception(*r.exc_info)), r.getMessage()
    for name, h in {**studio.sliders.handles, "time": studio.player.time}.items():
        assert h.min <= h.value <= h.max and math.isfinite(h.value), name
        assert type(h.value) is type(h.min), name
    assert studio.player.speed.value in studio.player.speed.options
    assert isinstance(studio.player.loop.value, bool)
    assert studio.player._thread.is_alive()
    assert studio.file.read_bytes() == studio.original  # nothing saved
    assert sorted(os.listdir(studio.file.parent)) == ["h.aou"]
    assert studio.inbox.refused > 0  # the sample did hold values the page never sends


def test_what_a_page_sends_breaks_no_page_and_changes_no_file(studio, capfd, caplog):
    _fuzz(studio, capfd, caplog, n=40, batch=20, seed=1)


@pytest.mark.slow
@pytest.mark.large
def test_what_a_page_sends_larger(studio, capfd, caplog):
    _fuzz(studio, capfd, caplog, n=300, batch=60, seed=2)
