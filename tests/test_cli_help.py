"""`gesturecast --help` opens with one plain line saying what the product does."""

import argparse
import importlib
import shlex
import subprocess
import sys

import pytest

import gesturecast
from gesturecast.cli import COMMANDS, build_parser, command_in
from gesturecast.cli_help import HELP
from gesturecast.tools.bench.bench_command import BENCHES


def test_help_opens_with_one_line_about_the_product():
    description = build_parser().description
    assert "\n" not in description and "``" not in description and "register" not in description
    assert description.startswith("Real-time avatar driver: speech")


def subcommands(parser) -> dict[str, str]:
    """command -> its line in ``gesturecast --help``."""
    return subcommands_of(next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)))


def subcommands_of(action) -> dict[str, str]:
    """sub-command -> its help line, of a sub-parsers action."""
    return {choice.dest: choice.help for choice in action._choices_actions}


def subcommand_parsers(parser) -> dict:
    """command -> its parser."""
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def test_the_command_table_lists_every_command_with_the_help_its_module_gives():
    assert subcommands(build_parser()) == {name: help_line for name, (_, help_line) in COMMANDS.items()}


def test_running_one_command_imports_no_other_command_module():
    code = ("import sys; from gesturecast.cli import build_parser; "
            "build_parser(only='generate').parse_args(['generate', 'a.wav', '-o', 'a.bvh']); "
            "print(sorted(m for m in sys.modules if m.startswith(('gesturecast.tools', 'scipy.signal', 'torch', "
            "'asyncio', 'websockets.asyncio', 'tqdm'))))")  # a server's and a progress bar's modules: not for a file
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"


HEAVY_PACKAGES = ("scipy", "onnxruntime", "torch", "matplotlib")


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["live", "--help"], ["generate", "--help"],
                                  ["demo", "--help"], ["bench", "--help"], ["eval", "--help"]])
def test_help_and_version_import_no_heavy_package(argv):
    """``--help`` and ``--version`` name no command and import none; the help of the commands a newcomer runs first
    loads no engine, and no command's help loads scipy or torch (`gesturecast bench startup` times them)."""
    heavy = ("scipy", "torch", "matplotlib") if argv[0] == "eval" else HEAVY_PACKAGES
    code = ("import contextlib, io, sys; from gesturecast.cli import main\n"
            "with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
            f"    main({argv!r})\n"
            f"print(sorted({{m.split('.')[0] for m in sys.modules}} & set({heavy!r})))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "[]"


def test_the_bench_table_lists_every_bench_with_the_help_its_module_gives():
    """`bench --help` lists the benches from the table; each module, imported when its bench runs, registers the
    same line."""
    registered = argparse.ArgumentParser().add_subparsers()
    for module, _ in BENCHES.values():
        importlib.import_module(module).register_bench(registered)
    assert subcommands_of(registered) == {name: help_line for name, (_, help_line) in BENCHES.items()}
    listed = subcommand_parsers(build_parser(only="bench"))["bench"]
    assert list(subcommands(listed)) == [*BENCHES, "startup"]


def test_a_named_bench_parses_its_own_flags():
    args = build_parser(only="bench").parse_args(["bench", "cues", "--words", "10"])
    assert args.bench == "cues" and args.words == [10] and callable(args.func)


def test_command_in_finds_the_command_after_global_options():
    assert command_in(["-v", "generate", "x.wav"]) == "generate" and command_in(["--help"]) is None


@pytest.fixture
def help_of(cli_here, monkeypatch):
    """A function: ``gesturecast COMMAND --help``'s text, printed by the CLI's main in this process at 80 columns."""
    monkeypatch.setenv("COLUMNS", "80")

    def text(*command: str) -> str:
        result = cli_here(*command, "--help")
        assert result.returncode == 0
        return result.stdout

    return text


@pytest.mark.parametrize("command", list(HELP))
def test_every_command_says_what_it_is_for_and_its_examples_parse(command):
    parser = build_parser(only=command)
    command_parser = subcommand_parsers(parser)[command]
    assert command_parser.description == HELP[command][0] and "examples:" in command_parser.epilog
    for example in HELP[command][1]:
        words = shlex.split(example)
        assert words[:2] == ["gesturecast", command]
        parser.parse_args(words[1:])  # every flag of the example exists and takes its value


@pytest.mark.parametrize("command", ["generate", "live", "serve", "train", "eval"])
def test_help_speaks_in_words_not_equations(command, help_of):
    text = help_of(command)
    for symbol in ("x̂", "δ", "s_a", "γ·", "batch row"):
        assert symbol not in text, symbol


def test_generate_help_names_every_csv_column(help_of):
    assert "transcript" in help_of("generate").split("--batch", 1)[1]


@pytest.mark.parametrize("command", ["live", "generate", "serve", "train", "eval-train", "export", "demo"])
def test_every_flag_has_help(command):
    parser = subcommand_parsers(build_parser(only=command))[command]
    bare = [action.option_strings[0] for action in parser._actions if action.option_strings and not action.help]
    assert not bare


def test_verbose_goes_before_or_after_the_command_and_version_answers(cli_here):
    parser = build_parser(only="generate")
    assert parser.parse_args(["generate", "a.wav", "-o", "a.bvh", "-v"]).verbose
    assert parser.parse_args(["-v", "generate", "a.wav", "-o", "a.bvh"]).verbose
    assert not getattr(parser.parse_args(["generate", "a.wav", "-o", "a.bvh"]), "verbose", False)
    assert cli_here("--version").stdout.strip() == f"gesturecast {gesturecast.__version__}"


@pytest.mark.parametrize("group", ["gestures", "data", "bench"])
def test_a_group_command_alone_prints_its_usage(group, cli_here):
    result = cli_here(group)
    assert result.returncode == 2 and "_command" not in result.stdout + result.stderr
    assert f"usage: gesturecast {group}" in result.stdout and "examples:" in result.stdout
