"""Headless Chromium for the viewer tests: the driver, canvas pixels, waiting, and a 30 fps frame feeder."""

from __future__ import annotations

import io
import shutil
import tempfile
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from gesturecast.bridges.websocket_server import WebSocketBridge
from gesturecast.frames import PoseFrame

CHROMIUM = Path("/usr/bin/chromium")
CHROMEDRIVER = Path("/usr/bin/chromedriver")
CHROMIUM_FLAGS = (
    "--headless", "--no-sandbox", "--disable-quic", "--no-first-run", "--disable-background-networking",
    "--disable-component-update", "--disable-sync", "--window-size=1000,900",
)
NO_GPU_FLAGS = ("--disable-gpu",)
WEBGL_FLAGS = ("--use-angle=swiftshader", "--enable-unsafe-swiftshader")  # software WebGL for the avatar
FEED_FPS = 30.0
PAGE_TIMEOUT_S = 30.0
SCREENSHOT_DIR = Path(tempfile.gettempdir()) / "gesturecast-viewer-screenshots"  # pictures the tests leave to look at

needs_chromium = pytest.mark.skipif(
    not (CHROMIUM.exists() and CHROMEDRIVER.exists()),
    reason="needs Debian packages chromium and chromium-driver (make system-deps)",
)


@contextmanager
def chromium(flags: tuple[str, ...]) -> Iterator[object]:
    """A selenium Chrome driver on a throwaway profile."""
    webdriver = pytest.importorskip("selenium.webdriver")
    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    profile = tempfile.mkdtemp(prefix="gesturecast-chromium-")
    for flag in (*CHROMIUM_FLAGS, *flags, f"--user-data-dir={profile}"):
        options.add_argument(flag)
    browser = webdriver.Chrome(service=webdriver.ChromeService(executable_path=str(CHROMEDRIVER)), options=options)
    try:
        yield browser
    finally:
        browser.quit()
        shutil.rmtree(profile, ignore_errors=True)


def canvas_pixels(driver, element_id: str = "stage") -> np.ndarray:
    png = driver.find_element("id", element_id).screenshot_as_png
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int32)  # (H, W, 3)


def wait_for(condition: Callable[[], bool], timeout_s: float = PAGE_TIMEOUT_S) -> None:
    deadline = time.monotonic() + timeout_s
    while not condition():
        if time.monotonic() > deadline:
            raise AssertionError("the page did not get there in time")
        time.sleep(0.1)


class Feeder(threading.Thread):
    """Plays ``make_frame(seq)`` into the bridge at 30 fps until stopped (the engine's role)."""

    def __init__(self, bridge: WebSocketBridge, make_frame: Callable[[int], PoseFrame]) -> None:
        super().__init__(daemon=True)
        self.bridge = bridge
        self.make_frame = make_frame
        self.stop_event = threading.Event()

    def run(self) -> None:
        seq = 0
        while not self.stop_event.wait(1.0 / FEED_FPS):
            self.bridge.send(self.make_frame(seq))
            seq += 1

    def __enter__(self) -> Feeder:
        self.start()
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.stop_event.set()
        self.join()
