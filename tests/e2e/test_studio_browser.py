"""The studio in a real browser: headless Chromium driven by Playwright.

Each test starts a studio in this process on a copy of a behaviour, opens its page and
works it as a user would (the sliders' number boxes, the Save button, an edit of the file
on disk); what the page shows is then checked against aou's own measurement of the
motion the studio holds.

The system's Chromium is used (Debian's ``chromium`` package: Playwright's own browser
download is not needed). Where none is found the tests are skipped, saying how to
install it. ``AOU_STUDIO_SCREENSHOT=docs/img/studio.png`` also saves the page as the
README shows it.
"""

from __future__ import annotations

import io
import os
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("viser", reason="the studio extra is missing: pip install '.[studio]'")
pytest.importorskip("playwright", reason="playwright is missing: pip install '.[test]'")

from aou_dsl.api import compile as aou_compile
from aou_dsl.api import lint, measure
from aou_dsl.lang.descriptors import REGISTRY
from tests.e2e.conftest import find_chromium, wait_for
from tests.integration.test_studio_forms import (
    PEEK,  # a sequence file: sliders scale its statements
)

ROOT = str(Path(__file__).resolve().parents[2])
CHROMIUM = find_chromium()
if CHROMIUM is None:
    pytest.skip("no Chromium found for the studio's browser tests: install Debian's "
                "(apt-get install -y chromium), or set AOU_CHROMIUM to a Chromium binary",
                allow_module_level=True)

pytestmark = pytest.mark.slow  # a browser rendering WebGL in software: about a minute each

#: Headless, no network chatter, WebGL in software (SwiftShader).
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--use-angle=swiftshader", "--enable-unsafe-swiftshader"]


@pytest.fixture(scope="module")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw, tempfile.TemporaryDirectory() as profile:
        ctx = pw.chromium.launch_persistent_context(
            profile, executable_path=CHROMIUM, args=ARGS, headless=True,
            viewport={"width": 1280, "height": 800})
        yield ctx
        ctx.close()


@pytest.fixture
def studio_of(tmp_path, browser):
    """``studio_of(name)``: a studio of a copy of ``behaviours/name.aou`` and its page."""
    from aou_dsl.studio.app import Studio

    made = []

    def start(name: str):
        path = tmp_path / f"{name}.aou"
        shutil.copy(os.path.join(ROOT, "behaviours", f"{name}.aou"), path)
        studio = Studio(str(path), port=0).start()
        made.append(studio)
        page = browser.new_page()
        page.goto(studio.url)
        page.locator("canvas").first.wait_for(timeout=60_000)
        page.locator("#aou-descriptors").wait_for(timeout=60_000)
        return studio, page, path

    yield start
    for page in browser.pages:  # a page left open renders on: the next tests starve
        page.close()
    for s in made:
        s.close()


def scene_canvas(page):
    """The 3D view's canvas: the largest on the page (some are off-screen helpers)."""
    sizes = page.locator("canvas").evaluate_all("cs => cs.map(c => c.width * c.height)")
    return page.locator("canvas").nth(int(np.argmax(sizes)))


def canvas(page) -> np.ndarray:
    from PIL import Image

    box = scene_canvas(page).bounding_box()
    png = page.screenshot(clip=box, animations="disabled")
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=float)


def settled(page) -> np.ndarray:
    """The canvas once two screenshots in a row agree (WebGL in software is slow)."""
    last = canvas(page)
    for _ in range(100):  # 30 s: a loaded machine draws WebGL in software slowly
        time.sleep(0.3)
        now = canvas(page)
        if np.abs(now - last).max() == 0:
            return now
        last = now
    return last


def number_box(page, label: str):
    """The number box beside the slider labelled ``label``."""
    slider = page.locator("label", has_text=label).first.get_attribute("for")
    return page.locator(f'div:has(> [id="{slider}"]) input:not([type=hidden])').first


def type_value(page, label: str, value: str) -> None:
    box = number_box(page, label)
    box.click()
    box.fill(value)
    box.press("Enter")


def measured_in_page(page, name: str) -> float | None:
    cell = page.locator(f'#aou-descriptors tr[data-descriptor="{name}"] td[data-measured]')
    if cell.count() == 0:
        return None
    return float(cell.first.get_attribute("data-measured"))


def test_the_canvas_draws_the_arm_and_it_moves(studio_of):
    studio, page, _ = studio_of("hesitant")
    page.get_by_role("button", name="Pause").click()
    wait_for(lambda: not studio.player.playing)
    studio.player.seek(0.0)
    start = settled(page)
    kind, a, b = studio.shown.trajectory.episodes[0]
    assert kind == "approach"
    studio.player.seek(b - studio.shown.trajectory.t[0])  # the end of the first approach
    later = settled(page)
    background = start[0, 0]
    drawn = np.abs(start - background).sum(axis=2) > 30
    assert drawn.mean() > 0.01  # the arm, the table and the path: not a blank canvas
    moved = np.abs(later - start).sum(axis=2) > 30
    assert moved.sum() > 200  # the arm drew somewhere else
    shot = os.environ.get("AOU_STUDIO_SCREENSHOT")
    if shot:  # the README's picture: playing, without the browser's own notices
        for close in page.locator(".mantine-Notification-closeButton").all():
            close.click()
        page.get_by_role("button", name="Play").click()
        wait_for(lambda: studio.player.playing)
        time.sleep(3)
        page.screenshot(path=shot)


def test_a_slider_rebuilds_and_the_motion_measures_the_new_value(studio_of):
    studio, page, path = studio_of("hesitant")
    before = path.read_text()
    first = studio.generation
    type_value(page, "pause_duration", "2.2")
    wait_for(lambda: studio.generation > first and "2.2s" in studio.shown.text)
    m = measure(studio.shown.trajectory)
    assert REGISTRY["pause_duration"].matches(2.2, m.descriptors["pause_duration"])
    assert m.descriptors["pause_count"] == 5  # the others as the file has them
    shown = wait_for(lambda: (v := measured_in_page(page, "pause_duration")) and
                     abs(v - 2.2) < 0.05 and v)
    assert shown == pytest.approx(m.descriptors["pause_duration"], abs=1e-6)
    assert path.read_text() == before  # nothing written before Save


def test_a_value_the_arm_cannot_give_shows_its_diagnostic(studio_of):
    studio, page, path = studio_of("fearful")
    good = studio.shown
    type_value(page, "shiver_amplitude", "20")
    item = page.locator('#aou-diagnostics li[data-code="C308"]')
    item.wait_for(timeout=60_000)
    assert "shiver" in item.inner_text() and "hint:" in item.inner_text()
    assert studio.shown is good  # the last good motion stays on screen
    assert measured_in_page(page, "shiver_amplitude") == pytest.approx(
        good.measured.descriptors["shiver_amplitude"])


def test_save_writes_a_file_that_lints_clean_and_compiles_to_the_motion_shown(studio_of):
    studio, page, path = studio_of("hesitant")
    before = path.read_text()
    first = studio.generation
    type_value(page, "retreat_distance", "0.08")
    wait_for(lambda: studio.generation > first and "0.08m" in studio.shown.text)
    page.get_by_role("button", name="Save").click()
    wait_for(lambda: path.read_text() != before)
    saved = path.read_text()
    assert saved == studio.shown.text
    assert saved.splitlines()[:2] == before.splitlines()[:2]  # the comments stay
    assert [ln for ln in saved.splitlines() if not ln.startswith("retreat")] == \
        [ln for ln in before.splitlines() if not ln.startswith("retreat")]
    result = lint(str(path))
    assert result.ok and not [d for d in result.diagnostics if d.severity != "note"]
    build = aou_compile(str(path))
    assert build.ok
    shown = studio.shown.trajectory
    assert np.array_equal(build.trajectory.t, shown.t)
    assert np.array_equal(build.trajectory.q, shown.q)
    assert REGISTRY["retreat_distance"].matches(
        0.08, build.measured.descriptors["retreat_distance"])
    assert not [p for p in os.listdir(path.parent) if p != path.name]  # nothing else


def test_editing_the_file_on_disk_reloads_the_motion(studio_of):
    studio, page, path = studio_of("hesitant")
    first = studio.generation
    text = path.read_text().replace("pause 1.67s x5", "pause 1.2s x5")
    path.write_text(text)  # as an editor saves it
    wait_for(lambda: studio.generation > first and studio.shown.text == text)
    m = measure(studio.shown.trajectory)
    assert REGISTRY["pause_duration"].matches(1.2, m.descriptors["pause_duration"])
    wait_for(lambda: (v := measured_in_page(page, "pause_duration")) is not None
             and abs(v - m.descriptors["pause_duration"]) < 1e-6)
    thumb = page.locator(f'[id="{page.locator("label", has_text="pause_duration").first.get_attribute("for")}"] [role="slider"]')  # noqa: E501
    wait_for(lambda: thumb.get_attribute("aria-valuenow") == "1.2")
    bad = text.replace("pause 1.2s x5", "pause 1.2s x3")  # too few pauses for 3 retreats
    path.write_text(bad)
    page.locator('#aou-diagnostics li[data-code="V121"]').wait_for(timeout=60_000)
    assert studio.shown.text == text  # the last good motion stays on screen


@pytest.fixture
def open_page(browser):
    """``open_page(studio)``: the studio's page, loaded; closed after the test (a page
    left open goes on rendering in software and starves the next tests)."""

    def start(studio):
        page = browser.new_page()
        page.goto(studio.url)
        page.locator("canvas").first.wait_for(timeout=60_000)
        page.locator("#aou-descriptors").wait_for(timeout=60_000)
        return page

    yield start
    for page in browser.pages:
        page.close()


def paused_at(page, studio, t: float) -> np.ndarray:
    """The 3D scene left of the control panel, settled, with the player paused at ``t``
    [s from the start] (the panel's own widgets change with the clock)."""
    if studio.player.playing:
        page.get_by_role("button", name="Pause").click()
        wait_for(lambda: not studio.player.playing)
    studio.player.seek(t)
    return scene_only(page, settled(page))


def scene_only(page, shot: np.ndarray) -> np.ndarray:
    # The panel's left edge, from a widget whose label never changes (the play button's
    # says Pause or Play, and a loaded page may not have redrawn it yet).
    panel = page.locator("label", has_text="Time [s]").first.bounding_box()
    origin = scene_canvas(page).bounding_box()
    return shot[:, :int(panel["x"] - origin["x"]) - 20]


def test_compare_draws_the_second_arm_ghosted_on_the_same_clock(tmp_path, open_page):
    from aou_dsl.studio.app import Studio

    for name in ("hesitant", "fearful"):
        shutil.copy(os.path.join(ROOT, "behaviours", f"{name}.aou"), tmp_path / f"{name}.aou")
    studio = Studio(str(tmp_path / "hesitant.aou"), port=0,
                    compare=str(tmp_path / "fearful.aou")).start()
    try:
        page = open_page(studio)
        a, b = studio.shown.trajectory, studio.other.trajectory
        # one clock for both: the page's time slider spans the longer motion
        thumb = page.locator(f'[id="{page.locator("label", has_text="Time [s]").first.get_attribute("for")}"] [role="slider"]')  # noqa: E501
        wait_for(lambda: thumb.get_attribute("aria-valuemax") ==
                 f"{round(max(a.duration, b.duration), 2):g}")
        kind, start, end = b.episodes[-1]  # the ghost's last episode: far from the other
        t = (start + end) / 2 - b.t[0]
        both = paused_at(page, studio, t)
        page.get_by_text("Show fearful.aou").click()  # the page's checkbox hides the ghost
        wait_for(lambda: not studio.ghost_box.value)

        def differs(shot: np.ndarray) -> np.ndarray:
            return np.abs(shot - both).sum(axis=2) > 30

        # A loaded machine draws WebGL in software slowly: wait for each change to be
        # drawn rather than take one frame (the test fails after wait_for's minute).
        def hidden() -> list[np.ndarray]:
            shot = scene_only(page, settled(page))
            return [shot] if differs(shot).sum() > 200 else []

        (alone,) = wait_for(hidden, timeout=90)
        ghost = differs(alone)
        assert ghost.sum() > 200, "the compared arm is not drawn"
        page.get_by_text("Show fearful.aou").click()
        wait_for(lambda: studio.ghost_box.value)
        # shown again: the ghost's pixels are back (most of them; software WebGL does not
        # always draw the same frame twice to the pixel)
        wait_for(lambda: (np.abs(scene_only(page, settled(page)) - alone).sum(axis=2) > 30)
                 .sum() > 0.5 * ghost.sum(), timeout=90)
        # the ghost moves with the clock
        later = paused_at(page, studio, 0.0)
        assert (np.abs(later - both).sum(axis=2) > 30).sum() > 200
    finally:
        studio.close()
    assert sorted(os.listdir(tmp_path)) == ["fearful.aou", "hesitant.aou"]


def test_a_recording_plays_in_the_page_with_its_measured_episodes(tmp_path, open_page):
    from aou_dsl.studio.app import Studio

    src = tmp_path / "hesitant.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), src)
    tr = aou_compile(str(src), check=False).trajectory
    rec = tmp_path / "rec.csv"  # a bare recording: joint columns, no goal, no episodes
    rows = ["t," + ",".join(tr.joint_names)] + [
        ",".join(f"{x:.6f}" for x in (t, *q)) for t, q in zip(tr.t, tr.q, strict=True)]
    rec.write_text("\n".join(rows) + "\n")
    studio = Studio(str(rec), robot="panda", port=0).start()
    try:
        page = open_page(studio)
        assert page.get_by_role("button", name="Save").count() == 0  # nothing to save
        assert page.get_by_text("Shape it").count() == 1 and studio.sliders.handles == {}
        m = measure(studio.shown.trajectory)
        for name in ("pause_count", "retreat_count", "pause_duration"):
            wait_for(lambda n=name: measured_in_page(page, n) is not None)
            assert measured_in_page(page, name) == pytest.approx(m.descriptors[name])
        assert (m.descriptors["pause_count"], m.descriptors["retreat_count"]) == (5, 3)
        titles = page.locator("svg title").all_text_contents()
        kinds = [t.split()[0] for t in titles]
        for kind in ("approach", "pause", "retreat"):  # each episode measured, in the page
            assert kinds.count(kind) >= sum(1 for e in m.episodes if e.kind == kind)
        shown = studio.shown.trajectory
        kind, _a, b = shown.episodes[0]
        start = paused_at(page, studio, 0.0)
        later = paused_at(page, studio, b - shown.t[0])
        drawn = np.abs(start - start[0, 0]).sum(axis=2) > 30
        assert drawn.mean() > 0.01
        assert (np.abs(later - start).sum(axis=2) > 30).sum() > 200  # the recorded arm moved
    finally:
        studio.close()
    assert sorted(os.listdir(tmp_path)) == ["hesitant.aou", "rec.csv"]




def test_a_sequence_gets_its_sliders_in_the_page_and_saves_them(tmp_path, open_page):
    from aou_dsl.studio.app import Studio

    path = tmp_path / "peek.aou"
    path.write_text(PEEK)
    studio = Studio(str(path), port=0).start()
    try:
        page = open_page(studio)
        for name in ("approach_acceleration", "pause_duration", "horizontal_gaze"):
            assert number_box(page, name).count() == 1
        assert page.locator("label", has_text="pause_count").count() == 0
        first = studio.generation
        type_value(page, "horizontal_gaze", "26")
        wait_for(lambda: studio.generation > first and "-26deg" in studio.shown.text)
        m = measure(studio.shown.trajectory)
        assert REGISTRY["horizontal_gaze"].matches(26.0, m.descriptors["horizontal_gaze"])
        wait_for(lambda: (v := measured_in_page(page, "horizontal_gaze")) is not None
                 and v == pytest.approx(m.descriptors["horizontal_gaze"]))
        page.get_by_role("button", name="Save").click()
        wait_for(lambda: path.read_text() != PEEK)
    finally:
        studio.close()
    assert path.read_text() == PEEK.replace("20deg", "26deg")
    build = aou_compile(str(path))
    assert build.ok and np.array_equal(build.trajectory.q, studio.shown.trajectory.q)


def test_fit_lists_the_fitted_values_in_the_page_and_fits_each_move(tmp_path, open_page):
    from aou_dsl.studio.app import Studio

    path = tmp_path / "fearful.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "fearful.aou"), path)
    path.write_text(path.read_text().replace("shiver 6deg for 1.25s",
                                             "shiver 6deg f=4Hz for 0.8s"))
    arm = tmp_path.parent / f"{tmp_path.name}-ur5.toml"  # its wrist follows 2.8 Hz
    arm.write_text('robot = "ur5"\njoint_accel = [5, 5, 5, 5, 5, 18]\n')
    studio = Studio(str(path), robot=str(arm), port=0, fit=True).start()
    try:
        page = open_page(studio)
        item = page.locator('#aou-fitted li[data-key="a"]')
        item.wait_for(timeout=60_000)
        assert "retreat_acceleration 2 " in item.inner_text()
        assert page.locator('#aou-fitted li[data-key="f"]').count() == 1
        type_value(page, "retreat_acceleration", "3")
        wait_for(lambda: "retreat_acceleration 3 " in item.inner_text())
        assert float(item.get_attribute("data-fitted")) < 2.0
        assert "retreat 0.06m a=3\n" in studio.shown.text and studio.shown.ok
    finally:
        studio.close()


#: A page of another site that tries to drive the studio: it opens the studio's websocket
#: (even knowing the token) and loads its page, and says what came of each.
FOREIGN = """<!doctype html><html><body><script>
window.result = {ws: "pending", page: "pending"};
const ws = new WebSocket("ws://127.0.0.1:PORT/?token=TOKEN", ["PROTOCOL"]);
ws.onopen = () => { window.result.ws = "open"; };
ws.onerror = () => { if (window.result.ws === "pending") window.result.ws = "refused"; };
ws.onclose = (e) => { if (window.result.ws === "pending") window.result.ws = "refused"; };
fetch("http://127.0.0.1:PORT/?token=TOKEN", {mode: "no-cors"})
  .then(() => { window.result.page = "answered"; })
  .catch(() => { window.result.page = "failed"; });
</script></body></html>"""


def test_a_page_of_another_origin_cannot_open_the_studios_websocket(tmp_path, browser):
    """A page served from another origin on this machine (another local server's port:
    Chromium's own local-network check stops a public site, not this) opens the studio's
    websocket knowing even its token, and is refused; the studio's own page connects."""
    import functools
    import http.server
    import threading

    import viser

    from aou_dsl.studio.app import Studio

    path = tmp_path / "h.aou"
    shutil.copy(os.path.join(ROOT, "behaviours", "hesitant.aou"), path)
    before = path.read_bytes()
    studio = Studio(str(path), port=0).start()
    site = tmp_path.parent / f"{tmp_path.name}-site"
    site.mkdir()
    (site / "index.html").write_text(
        FOREIGN.replace("PORT", str(studio.port)).replace("TOKEN", studio.gate.token)
        .replace("PROTOCOL", f"viser-v{viser.__version__}"))
    other = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(
        http.server.SimpleHTTPRequestHandler, directory=str(site)))
    threading.Thread(target=other.serve_forever, daemon=True).start()
    page = browser.new_page()
    try:
        connected = []
        studio.server.on_client_connect(lambda client: connected.append(client))
        page.goto(f"http://127.0.0.1:{other.server_address[1]}/")
        result = wait_for(lambda: (r := page.evaluate("window.result"))["ws"] != "pending"
                          and r["page"] != "pending" and r)
        assert result["ws"] == "refused"
        time.sleep(1.0)
        assert connected == []  # the studio never saw a page from there
        assert studio.inbox.refused == 0
        # the studio's own page, in the same browser, still connects
        page.goto(studio.url)
        page.locator("#aou-descriptors").wait_for(timeout=60_000)
        assert len(connected) == 1
    finally:
        page.close()
        other.shutdown()
        other.server_close()
        studio.close()
    assert path.read_bytes() == before and os.listdir(tmp_path) == ["h.aou"]


def _live_state(page) -> str | None:
    return page.locator("#aou-live").first.get_attribute("data-state")


def test_a_scenario_plays_live_and_dragging_the_card_over_the_tag_makes_the_arm_hesitant(
        browser, tmp_path):
    """``aouc studio SCENARIO.toml`` in a browser: the camera's view, the confidence and
    the C-V map are in the page; typing the card's place over the tag into its slider
    walks the state the page shows from confident towards hesitant, and taking it away
    brings confident back."""
    from aou_dsl.studio.stage import Stage
    from tests.e2e.test_studio_live import AWAY, OVER, STILL

    path = tmp_path / "still.toml"
    path.write_text(STILL)
    stage = Stage(str(path), port=0).start()
    page = browser.new_page()
    try:
        page.goto(stage.url)
        page.locator("canvas").first.wait_for(timeout=60_000)
        page.locator('#aou-live[data-state="confident"]').wait_for(timeout=60_000)
        for part in ("#aou-camera", "#aou-confidence", "#aou-cv"):
            assert page.locator(part).count() == 1, part
        seen: list[str] = []

        def state_is(want: str) -> bool:
            got = _live_state(page)
            if got and (not seen or seen[-1] != got):
                seen.append(got)
            return got == want

        assert state_is("confident")
        type_value(page, "card y [m]", str(OVER))
        wait_for(lambda: state_is("hesitant"), timeout=90)
        order = ["confident", "curious", "hesitant"]
        assert [order.index(s) for s in seen] == sorted(order.index(s) for s in seen), seen
        assert page.locator('#aou-camera').first.get_attribute("data-visible") == "0.000"
        type_value(page, "card y [m]", str(AWAY))
        wait_for(lambda: state_is("confident"), timeout=90)
        assert stage.scene_at(0.0).occluders[0].center[1] == AWAY
    finally:
        page.close()
        stage.close()
