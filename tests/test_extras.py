"""A missing optional extra is named in one line: the training commands without torch, the Pipecat processor
without Pipecat (each run in an interpreter where the module cannot be imported, as where it is not installed)."""

from __future__ import annotations

import subprocess
import sys

import pytest

# argv[1]: the top-level module to hide; the rest: the code to run
HIDE_AND_RUN = """
import sys

class Missing:
    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] == sys.argv[1]:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)

sys.meta_path.insert(0, Missing())
exec(sys.argv[2])
"""
RUN_CLI = "from gesturecast.cli import main; sys.exit(main(sys.argv[3:]))"


def run_without(module: str, code: str, *argv: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", HIDE_AND_RUN, module, code, *argv], capture_output=True, text=True,
                          timeout=120, cwd=cwd)


@pytest.mark.parametrize("argv", [["train", "--preset", "tiny"], ["eval-train"], ["export", "work", "-o", "out"]])
def test_training_commands_without_torch_name_the_extra_in_one_line(argv, tmp_path):
    (tmp_path / "work").mkdir()
    result = run_without("torch", RUN_CLI, *argv, cwd=tmp_path)
    assert result.returncode == 2, result.stderr
    assert result.stderr.splitlines() == [f"gesturecast {argv[0]}: error: torch is not installed; this needs it: "
                                          "pip install torch==2.13.0 && pip install 'gesturecast[train]'"]


def test_the_pipecat_import_without_pipecat_names_the_extra():
    result = run_without("pipecat", "from gesturecast.pipecat import GesturecastProcessor")
    assert result.returncode == 1
    assert result.stderr.splitlines()[-1] == ("ModuleNotFoundError: Pipecat is not installed; this needs it: "
                                              "pip install 'gesturecast[pipecat]'")


def test_the_short_pipecat_import_is_the_processor():
    pytest.importorskip("pipecat")
    from gesturecast.pipecat import GesturecastProcessor
    from gesturecast.realtime.agents.pipecat_processor import GesturecastProcessor as Processor

    assert GesturecastProcessor is Processor
