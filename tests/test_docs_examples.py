"""Every fenced code block of README.md and docs/*.md: python and bash blocks run as written, in a folder holding the
files they name (tests/docs_blocks.py); data blocks parse; command synopses name only flags the command has."""

from __future__ import annotations

import functools
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from docs_blocks import (
    DATA_LANGUAGES,
    PAGES,
    RUNNABLE,
    SECONDS,
    Block,
    all_blocks,
    bash_script,
    build_folder,
    command_lines,
    command_words,
    distinct_runs,
    fence_count,
    shared_data_folder,
    with_free_ports,
)

from gesturecast.models.motion.bvh import read_bvh

BLOCKS = all_blocks()
RUN = [block for block in BLOCKS if block.language in RUNNABLE and block.skip is None]
DISTINCT_RUNS = distinct_runs(RUN)  # the same commands on two pages run once
SKIP_REASONS = ("needs a microphone", "needs the network", "needs several machines", "runs this test suite")
MAX_SKIPPED = 6
TIMEOUT_S = 600
FLAG = re.compile(r"(?<![\w-])(--[a-z][a-z0-9-]*)")


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    return build_folder(tmp_path_factory.mktemp("examples"), shared_data_folder())


@pytest.fixture(scope="module")
def dataset_cache(folder) -> Path:
    """.cache/dataset in the folder, from one take per dataset of the training data (skipped where it is absent)."""
    if shared_data_folder() is None:
        pytest.skip("the training data folder is absent")
    subprocess.run([sys.executable, "-m", "gesturecast.cli", "data", "build", "--shared", "DATA", "--limit", "1"],
                   cwd=folder, check=True, capture_output=True)
    return folder / ".cache" / "dataset"


def run_block(block: Block, folder: Path, base_env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    """Run one block in ``folder`` with this interpreter's environment first on PATH (python, gesturecast)."""
    base_env = base_env or dict(os.environ)
    env = {**base_env, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{base_env['PATH']}"}
    if block.language == "python":
        command = [sys.executable, "-c", with_free_ports(block.code)]
    else:
        command = ["bash", "-c", bash_script(block.code)]
    return subprocess.run(command, cwd=folder, env=env, capture_output=True, text=True, timeout=TIMEOUT_S)


def test_every_fence_has_a_language_and_every_block_parses():
    for page in PAGES:
        assert 2 * sum(block.page == page for block in BLOCKS) == fence_count(page), page
    untagged = [block.name for block in BLOCKS if block.language not in RUNNABLE + DATA_LANGUAGES]
    assert not untagged, f"fences without a known language: {untagged}"


def test_blocks_are_skipped_rarely_and_only_for_what_a_test_cannot_have():
    skipped = [block for block in BLOCKS if block.skip is not None]
    assert len(skipped) <= MAX_SKIPPED, [block.name for block in skipped]
    for block in skipped:
        assert block.skip in SKIP_REASONS, f"{block.name}: {block.skip!r}"


@pytest.mark.parametrize("block", [block for block in BLOCKS if block.language == "json"], ids=lambda b: b.name)
def test_json_blocks_parse(block):
    json.loads(block.code)


@pytest.mark.parametrize("block", [block for block in BLOCKS if block.language == "yaml"], ids=lambda b: b.name)
def test_yaml_blocks_parse(block):
    yaml = pytest.importorskip("yaml")  # Ray's dependency: there where the `scale` extra is installed
    assert isinstance(yaml.safe_load(block.code), dict)


@functools.cache
def help_text(*command: str) -> str:
    return subprocess.run([sys.executable, "-m", "gesturecast.cli", *command, "--help"], capture_output=True,
                          text=True, check=True).stdout


@pytest.mark.parametrize("block", [block for block in BLOCKS if block.language == "text"
                                   and command_lines(block.code)], ids=lambda b: b.name)
def test_commands_shown_as_text_name_only_flags_the_command_has(block):
    """Synopses and the records of long runs (study pages) are not run; every flag they name must exist."""
    for line in command_lines(block.code):
        command = command_words(line)
        text = help_text(*command)
        missing = sorted({flag for flag in FLAG.findall(line) if not re.search(rf"{flag}(?![\w-])", text)})
        assert not missing, f"{block.name}: `gesturecast {' '.join(command)}` has no {missing}"


@pytest.mark.parametrize("block", DISTINCT_RUNS, ids=lambda b: b.name)
def test_block_runs(block, folder, request):
    """Blocks that read the training data are skipped where it is absent (as the tests that need it are); the
    microphone that ``gesturecast devices`` lists is a virtual one (tests/conftest.py)."""
    if block.needs_data:
        request.getfixturevalue("dataset_cache")
    env = request.getfixturevalue("virtual_mic").env if block.needs_microphone else None
    result = run_block(block, folder, env)
    assert result.returncode == 0, f"{block.name}:\n{result.stdout[-1500:]}\n{result.stderr[-3000:]}"


def test_the_streaming_example_changes_style_and_records_every_frame(folder):
    stream_block = next(block for block in RUN if "gesturecast.Stream(" in block.code and block.page == "README.md")
    (folder / "live.bvh").unlink(missing_ok=True)
    result = run_block(stream_block, folder)
    assert result.returncode == 0, result.stderr[-2000:]
    styles = [line.split()[1] for line in result.stdout.splitlines()[1:]]
    assert "delay your audio by" in result.stdout and styles[0] == "old" and styles[-1] == "happy"
    assert read_bvh(folder / "live.bvh").num_frames == SECONDS * 30


@pytest.mark.parametrize("block", [block for block in BLOCKS if block.language == "text"
                                   and block.code.startswith("latency L = ")], ids=lambda b: b.name)
def test_the_latency_line_shown_is_the_one_the_engine_prints(block):
    from gesturecast.realtime.run.engine_setup import build_session
    from gesturecast.realtime.timing.clock import MonotonicClock
    from gesturecast.settings import Settings

    printed = build_session(Settings(), MonotonicClock()).budget.describe()
    assert block.code.splitlines()[0] == printed
