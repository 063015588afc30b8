"""The CI workflow for Windows and macOS installs with pip alone (no torch) and runs test paths that exist."""

from __future__ import annotations

from pathlib import Path

import pytest

yaml = pytest.importorskip("yaml")

ROOT = Path(__file__).resolve().parents[1]
WORKFLOW = ROOT / ".github" / "workflows" / "runtime-tests.yml"


def steps() -> list[dict]:
    workflow = yaml.safe_load(WORKFLOW.read_text(encoding="utf-8"))
    job = workflow["jobs"]["runtime"]
    assert set(job["strategy"]["matrix"]["os"]) == {"windows-latest", "macos-latest"}
    return job["steps"]


def test_the_workflow_installs_with_pip_and_without_torch():
    commands = " ".join(step.get("run", "") for step in steps())
    assert "pip install -e \".[dev]\"" in commands and "torch" not in commands and "apt-get" not in commands


def test_every_test_path_of_the_workflow_exists():
    command = next(step["run"] for step in steps() if "pytest" in step.get("run", ""))
    paths = [word for word in command.split() if word.startswith("tests")]
    assert paths and all((ROOT / path).exists() for path in paths), paths
