"""``gesturecast bench startup`` times every command's help and ``--version`` as separate processes."""

from gesturecast.cli import COMMANDS
from gesturecast.tools.bench.bench_command import command_lines, command_names, timing


def test_every_command_line_is_timed_help_and_version_first():
    lines = command_lines()
    assert lines[:2] == [("--help",), ("--version",)]
    assert [line[0] for line in lines[2:]] == list(COMMANDS) and all(line[1] == "--help" for line in lines[2:])


def test_the_commands_are_read_from_the_help_also_when_a_help_line_wraps():
    help_text = "usage: x\n\npositional arguments:\n  COMMAND\n    live       speech in\n    generate   offline:\n" \
                "               --batch: a folder\n\noptions:\n  -h\n"
    assert command_names(help_text) == ["live", "generate"]


def test_a_timing_names_its_command_line_and_its_median_and_slowest_run():
    result = timing(("--version",), repeats=2)
    assert result["command"] == "gesturecast --version" and 0 < result["median_s"] <= result["max_s"]
