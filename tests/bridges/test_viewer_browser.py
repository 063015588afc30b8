"""The browser viewer in real headless Chromium: it receives frames, shows latency, the figure moves."""

from __future__ import annotations

import time

import numpy as np
import pytest
from bridge_test_frames import moving_frame
from browser_session import NO_GPU_FLAGS, SCREENSHOT_DIR, Feeder, canvas_pixels, chromium, needs_chromium, wait_for
from PIL import Image

from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.controls import Gesture, wire
from gesturecast.realtime.gestures.lexicon import load_lexicon

SCREENSHOT_GAP_S = 0.6
CHANGED_PIXEL_THRESHOLD = 40  # summed RGB difference that counts as a changed pixel
SETTLE_S = 0.5  # the page redraws after a click
FIGURE_SATURATION = 80  # max − min channel: the figure's blue, orange and yellow; the floor and background are grey

pytestmark = needs_chromium


@pytest.fixture
def driver():
    with chromium(NO_GPU_FLAGS) as browser:
        yield browser


def test_viewer_draws_moving_figure_and_latency(driver):
    bridge = WebSocketBridge(WebSocketConfig(port=0, style_choices=("relaxed", "happy"))).start()
    try:
        with Feeder(bridge, lambda seq: moving_frame(seq, style="relaxed")):
            driver.get(bridge.url)
            wait_for(lambda: int(driver.find_element("id", "frames").text or 0) >= 10)
            first = canvas_pixels(driver)
            time.sleep(SCREENSHOT_GAP_S)
            second = canvas_pixels(driver)
            latency_ms = float(driver.find_element("id", "latency").get_attribute("data-ms"))
            style = driver.find_element("id", "style").text
        SCREENSHOT_DIR.mkdir(exist_ok=True)
        Image.fromarray(second.astype(np.uint8)).save(SCREENSHOT_DIR / "viewer.png")
    finally:
        bridge.close()
    changed = np.abs(first - second).sum(axis=-1) > CHANGED_PIXEL_THRESHOLD  # (H, W)
    lit = (second.sum(axis=-1) > first.mean(axis=(0, 1)).sum() + CHANGED_PIXEL_THRESHOLD)  # figure strokes
    assert lit.sum() > 100, "no figure drawn on the canvas"
    assert changed.sum() > 50, "the figure did not move between screenshots"
    assert 0.0 < latency_ms < 10_000.0
    assert style == "relaxed"


def test_viewer_controls_send_only_the_sliders_the_user_moved(driver):
    received: list[dict] = []
    bridge = WebSocketBridge(WebSocketConfig(port=0, style_choices=("relaxed", "happy")), on_control=received.append)
    bridge.start()
    try:
        driver.get(bridge.url)
        wait_for(lambda: driver.execute_script("return document.getElementById('style-select').options.length") > 1)
        driver.execute_script(
            "const s = document.getElementById('audio_guidance'); s.value = '2.5';"
            "s.dispatchEvent(new Event('input'));"
        )
        driver.find_element("id", "style-select").send_keys("happy")
        driver.find_element("id", "apply").click()
        wait_for(lambda: len(received) >= 1)
    finally:
        bridge.close()
    assert wire(received[0]) == {"audio_guidance": 2.5, "style": "happy"}  # guidance untouched: not sent


def test_viewer_preselects_the_style_and_sends_free_text_as_a_prompt(driver):
    received: list[dict] = []
    config = WebSocketConfig(port=0, style="relaxed", style_choices=("happy", "relaxed"))
    bridge = WebSocketBridge(config, on_control=received.append).start()
    try:
        driver.get(bridge.url)
        wait_for(lambda: driver.find_element("id", "style").text == "relaxed")
        selected = driver.execute_script("return document.getElementById('style-select').value")
        driver.find_element("id", "style-text").send_keys("happy, sweeping gestures")
        driver.find_element("id", "apply").click()
        wait_for(lambda: len(received) >= 1)
    finally:
        bridge.close()
    assert selected == "relaxed"
    assert wire(received[0]) == {"prompt": "happy, sweeping gestures"}


def test_viewer_root_selector_sends_the_chosen_root_mode(driver):
    received: list[dict] = []
    bridge = WebSocketBridge(WebSocketConfig(port=0, style_choices=("relaxed",)), on_control=received.append).start()
    try:
        driver.get(bridge.url)
        wait_for(lambda: driver.execute_script("return document.getElementById('root').options.length") == 4)
        driver.find_element("id", "root").send_keys("locked")
        driver.find_element("id", "apply").click()
        wait_for(lambda: len(received) >= 1)
    finally:
        bridge.close()
    assert wire(received[0]) == {"root": "locked"}


def test_viewer_part_selectors_send_part_styles(driver):
    received: list[dict] = []
    config = WebSocketConfig(port=0, style_choices=("relaxed", "happy", "old"), body_parts=("arms", "torso", "legs"))
    bridge = WebSocketBridge(config, on_control=received.append).start()
    try:
        driver.get(bridge.url)
        wait_for(lambda: driver.execute_script("return document.getElementById('part-legs') !== null"))
        hidden = driver.execute_script("return document.getElementById('part-styles').hidden")
        driver.find_element("id", "part-arms").send_keys("happy")
        driver.find_element("id", "part-legs").send_keys("old")
        driver.find_element("id", "apply").click()
        wait_for(lambda: len(received) >= 1)
        driver.find_element("id", "part-arms").send_keys("(whole")
        driver.find_element("id", "part-legs").send_keys("(whole")
        driver.find_element("id", "apply").click()
        wait_for(lambda: len(received) >= 2)
    finally:
        bridge.close()
    assert not hidden
    assert wire(received[0]) == {"part_styles": {"arms": "happy", "legs": "old"}}
    assert wire(received[1]) == {"part_styles": {}}  # every part back on the whole-body style


def test_viewer_gesture_buttons_send_a_gesture_control(driver):
    received: list[dict] = []
    config = WebSocketConfig(port=0, style_choices=("happy",), gestures=("wave", "bow"))
    bridge = WebSocketBridge(config, on_control=received.append).start()
    try:
        driver.get(bridge.url)
        wait_for(lambda: driver.execute_script("return document.querySelectorAll('#gestures button').length") == 2)
        driver.find_element("css selector", "#gestures button[data-gesture='bow']").click()
        wait_for(lambda: len(received) >= 1)
    finally:
        bridge.close()
    assert received == [(Gesture("bow"),)]


def test_viewer_without_body_parts_shows_no_part_selectors(driver):
    bridge = WebSocketBridge(WebSocketConfig(port=0, style_choices=("relaxed",))).start()
    try:
        driver.get(bridge.url)
        wait_for(lambda: driver.execute_script("return document.getElementById('style-select').options.length") > 1)
        hidden = driver.execute_script("return document.getElementById('part-styles').hidden")
    finally:
        bridge.close()
    assert hidden


def figure_pixels(image: np.ndarray) -> int:
    """How many pixels of a (H, W, 3) picture have the stick figure's colours."""
    return int((image.max(axis=-1) - image.min(axis=-1) > FIGURE_SATURATION).sum())


def test_unticking_the_stick_figure_without_an_avatar_hides_it(driver):
    """No avatar on the server: the box is ticked and the figure drawn; unticked, the stage keeps its floor and the
    drop hint but no figure (it used to stay drawn); ticked again, the figure is back."""
    bridge = WebSocketBridge(WebSocketConfig(port=0)).start()  # no avatar
    try:
        with Feeder(bridge, moving_frame):
            driver.get(bridge.url)
            wait_for(lambda: driver.execute_script("return document.body.dataset.avatar") == "none")
            wait_for(lambda: int(driver.find_element("id", "frames").text or 0) >= 10)
            ticked = canvas_pixels(driver)
            box = driver.find_element("id", "show-stick")
            box.click()
            time.sleep(SETTLE_S)
            unticked, still_ticked = canvas_pixels(driver), box.is_selected()
            hint = driver.find_element("id", "drop-hint").is_displayed()
            box.click()
            time.sleep(SETTLE_S)
            ticked_again = canvas_pixels(driver)
    finally:
        bridge.close()
    assert figure_pixels(ticked) > 300 and figure_pixels(ticked_again) > 300
    assert not still_ticked and hint
    assert figure_pixels(unticked) == 0, "the stick figure is still drawn with its box unticked"


def test_at_1280_by_800_the_gesture_buttons_and_the_size_dial_show_without_scrolling(driver):
    """A laptop screen: every button of the bundled lexicon, the gesture size and the pause are in view (the picture
    is left in SCREENSHOT_DIR as viewer-1280x800.png)."""
    names = tuple(entry.name for entry in load_lexicon())
    config = WebSocketConfig(port=0, style_choices=("neutral", "happy", "sad", "old"),
                             body_parts=("arms", "torso", "legs"), gestures=names)
    bridge = WebSocketBridge(config).start()
    driver.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                           {"width": 1280, "height": 800, "deviceScaleFactor": 1, "mobile": False})
    try:
        with Feeder(bridge, lambda seq: moving_frame(seq, style="neutral")):
            driver.get(bridge.url)
            wait_for(lambda: driver.execute_script("return document.querySelectorAll('#gestures button').length")
                     == len(names))
            bottoms = driver.execute_script(
                "return [...document.querySelectorAll('#gestures button, #intensity, #pause')]"
                ".map(e => e.getBoundingClientRect().bottom)")
            SCREENSHOT_DIR.mkdir(exist_ok=True)
            driver.save_screenshot(str(SCREENSHOT_DIR / "viewer-1280x800.png"))
    finally:
        bridge.close()
    assert len(bottoms) == len(names) + 2 and max(bottoms) <= 800


def test_the_gesture_size_and_pause_are_sent_at_once(driver):
    received: list[dict] = []
    bridge = WebSocketBridge(WebSocketConfig(port=0, style_choices=("happy",)), on_control=received.append).start()
    try:
        driver.get(bridge.url)
        wait_for(lambda: driver.execute_script("return document.getElementById('intensity').max") == "2")
        driver.execute_script("const s = document.getElementById('intensity'); s.value = '0.25';"
                              "s.dispatchEvent(new Event('input')); s.dispatchEvent(new Event('change'));")
        driver.find_element("id", "pause").click()
        driver.find_element("id", "pause").click()
        wait_for(lambda: len(received) >= 3)
    finally:
        bridge.close()
    assert [wire(control) for control in received] == [{"intensity": 0.25}, {"pause": True}, {"pause": False}]
