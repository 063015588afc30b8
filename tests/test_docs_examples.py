"""The Python examples of the README and docs/python-api.md run as written (in a folder holding ``talk.wav``)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
import soundfile

from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import read_bvh

REPO_ROOT = Path(__file__).resolve().parents[1]
PAGES = ("README.md", "docs/python-api.md")
PYTHON_BLOCK = re.compile(r"```python\n(.*?)```", re.S)
SECONDS = 3


def python_blocks(page: str) -> list[str]:
    return PYTHON_BLOCK.findall((REPO_ROOT / page).read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """A working folder with 3 s of speech as talk.wav (48 kHz stereo, as a user's recording might be)."""
    import soxr

    folder = tmp_path_factory.mktemp("examples")
    speech = load_audio(PACKAGED_SAMPLE)[: SECONDS * SAMPLE_RATE]
    stereo = soxr.resample(speech, SAMPLE_RATE, 48000)[:, None].repeat(2, axis=1)  # (n, 2)
    soundfile.write(folder / "talk.wav", stereo, 48000)
    return folder


@pytest.mark.parametrize("page", PAGES)
def test_every_python_example_runs(page, folder):
    blocks = python_blocks(page)
    assert len(blocks) >= 2  # the offline call and the stream
    for number, code in enumerate(blocks):
        (folder / "talk.bvh").unlink(missing_ok=True)
        (folder / "live.bvh").unlink(missing_ok=True)
        result = subprocess.run([sys.executable, "-c", code], cwd=folder, capture_output=True, text=True,
                                timeout=300)
        assert result.returncode == 0, f"{page} example {number + 1}:\n{result.stderr[-2000:]}"
        written = folder / ("talk.bvh" if number == 0 else "live.bvh")
        assert read_bvh(written).num_frames == SECONDS * 30, f"{page} example {number + 1} wrote {written.name}"
    assert "delay your audio by" in result.stdout and " happy " in result.stdout
