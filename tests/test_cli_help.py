"""`gesturecast --help` opens with one plain line saying what the product does."""

import subprocess
import sys

from gesturecast.cli import COMMANDS, build_parser, command_in


def test_help_opens_with_one_line_about_the_product():
    description = build_parser().description
    assert "\n" not in description and "``" not in description and "register" not in description
    assert description.startswith("Real-time avatar driver: speech")


def subcommands(parser) -> dict[str, str]:
    """command -> its line in ``gesturecast --help``."""
    action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return {choice.dest: choice.help for choice in action._choices_actions}


def test_the_command_table_lists_every_command_with_the_help_its_module_gives():
    assert subcommands(build_parser()) == {name: help_line for name, (_, help_line) in COMMANDS.items()}


def test_running_one_command_imports_no_other_command_module():
    code = ("import sys; from gesturecast.cli import build_parser; "
            "build_parser(only='generate').parse_args(['generate', 'a.wav', '-o', 'a.bvh']); "
            "print(sorted(m for m in sys.modules if m.startswith(('gesturecast.tools', 'scipy.signal', 'torch'))))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"


def test_command_in_finds_the_command_after_global_options():
    assert command_in(["-v", "generate", "x.wav"]) == "generate" and command_in(["--help"]) is None
