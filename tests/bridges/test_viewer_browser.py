"""The browser viewer in real headless Chromium: it receives frames, shows latency, the figure moves."""

from __future__ import annotations

import io
import shutil
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from bridge_test_frames import moving_frame
from PIL import Image

from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig

CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = Path("/usr/bin/chromedriver")
CHROMIUM_FLAGS = (
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync", "--window-size=1000,720",
)
FEED_FPS = 30.0
PAGE_TIMEOUT_S = 30.0
SCREENSHOT_GAP_S = 0.6
CHANGED_PIXEL_THRESHOLD = 40  # summed RGB difference that counts as a changed pixel
SCREENSHOT_DIR = Path(tempfile.gettempdir()) / "gesturecast-viewer-screenshots"

pytestmark = pytest.mark.skipif(
    not (CHROMIUM.exists() and CHROMEDRIVER.exists()),
    reason="needs Debian packages chromium and chromium-driver (make system-deps)",
)


class Feeder(threading.Thread):
    """Plays moving frames into the bridge at 30 fps until stopped (the engine's role)."""

    def __init__(self, bridge: WebSocketBridge) -> None:
        super().__init__(daemon=True)
        self.bridge = bridge
        self.stop_event = threading.Event()

    def run(self) -> None:
        seq = 0
        while not self.stop_event.wait(1.0 / FEED_FPS):
            self.bridge.send(moving_frame(seq, style="relaxed"))
            seq += 1


@pytest.fixture
def driver():
    webdriver = pytest.importorskip("selenium.webdriver")
    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    profile = tempfile.mkdtemp(prefix="gesturecast-chromium-")
    for flag in (*CHROMIUM_FLAGS, f"--user-data-dir={profile}"):
        options.add_argument(flag)
    browser = webdriver.Chrome(service=webdriver.ChromeService(executable_path=str(CHROMEDRIVER)), options=options)
    yield browser
    browser.quit()
    shutil.rmtree(profile, ignore_errors=True)


def canvas_pixels(driver) -> np.ndarray:
    png = driver.find_element("id", "stage").screenshot_as_png
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int32)  # (H, W, 3)


def wait_for(condition, timeout_s: float = PAGE_TIMEOUT_S) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError("the page did not get there in time")
        time.sleep(0.1)


def test_viewer_draws_moving_figure_and_latency(driver):
    bridge = WebSocketBridge(WebSocketConfig(port=0, style_choices=("relaxed", "happy"))).start()
    feeder = Feeder(bridge)
    feeder.start()
    try:
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
        feeder.stop_event.set()
        feeder.join()
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
    assert received[0] == {"audio_guidance": 2.5, "style": "happy"}  # guidance untouched: not sent


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
    assert received[0] == {"prompt": "happy, sweeping gestures"}


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
    assert received[0] == {"root": "locked"}
