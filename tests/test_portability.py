"""The runtime on Windows: with the Linux-only modules and calls missing, every command still registers and every
module of the live path (gesturecast, realtime, bridges, the model runtime and audio features) imports as it does
here (only that difference is checked: a module that does not import here either is other tests' business); and
output in a narrow Windows code page does not fail."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from gesturecast.realtime.jobs import batch

IMPORT_TIMEOUT_S = 120

# run in a fresh interpreter (argv[1] == "windows": first take away what Windows lacks); prints, as JSON, the
# import error of the command line and of each module of the live path (None: imported)
IMPORT_ALL = """
import importlib, json, multiprocessing, os, pkgutil, signal, sys

if sys.argv[1] == "windows":
    for name in ("resource", "fcntl", "termios", "pwd", "grp"):
        sys.modules[name] = None  # `import resource` now raises ImportError, as on Windows
    for name in ("sched_getaffinity", "sched_setaffinity", "fork", "forkpty", "getuid", "geteuid", "killpg", "setsid",
                 "getpgid", "nice", "mkfifo", "getloadavg"):
        if hasattr(os, name):
            delattr(os, name)
    for name in ("SIGHUP", "SIGKILL", "SIGQUIT", "SIGUSR1", "SIGUSR2", "SIGPIPE", "SIGCHLD", "SIGALRM"):
        if hasattr(signal, name):
            delattr(signal, name)
    multiprocessing.get_all_start_methods = lambda: ["spawn"]

def error_of(action):
    try:
        action()
    except Exception as error:
        return f"{type(error).__name__}: {error}"
    return None

errors = {"gesturecast.cli.build_parser()": error_of(lambda: importlib.import_module("gesturecast.cli").build_parser())}
LIVE_PATH = ("gesturecast", "gesturecast.realtime", "gesturecast.bridges", "gesturecast.models.runtime",
             "gesturecast.models.audio")
for package_name in LIVE_PATH:
    if importlib.util.find_spec(package_name) is None:
        continue  # not (or no longer) a package of this layout
    package = importlib.import_module(package_name)
    for module in pkgutil.walk_packages(package.__path__, package_name + "."):
        if ".agents" in module.name or "ray" in module.name:
            continue  # optional extras (Pipecat, Ray), imported only by their own commands
        errors[module.name] = error_of(lambda: importlib.import_module(module.name))
print(json.dumps(errors))
"""


def import_errors(platform: str) -> dict[str, str | None]:
    result = subprocess.run([sys.executable, "-c", IMPORT_ALL, platform], capture_output=True, text=True,
                            timeout=IMPORT_TIMEOUT_S)
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads(result.stdout.splitlines()[-1])


def test_the_cli_and_the_live_path_import_without_linux_only_modules():
    here, windows = import_errors("as-is"), import_errors("windows")
    assert len(here) > 50 and here.keys() == windows.keys()
    assert here["gesturecast.cli.build_parser()"] is None
    broken = {name: error for name, error in windows.items() if error is not None and here[name] is None}
    assert broken == {}


@pytest.mark.skipif(sys.platform == "win32", reason="Windows has no forkserver")
def test_batch_workers_use_forkserver_where_it_exists():
    assert batch.PROCESS_START_METHOD == "forkserver"


def test_help_written_to_a_narrow_code_page_does_not_fail():
    """Windows writes redirected output in its ANSI code page: cp1252 has no "→" of the command list."""
    env = {**os.environ, "PYTHONIOENCODING": "cp1252"}
    result = subprocess.run([sys.executable, "-m", "gesturecast.cli", "--help"], capture_output=True, env=env,
                            timeout=IMPORT_TIMEOUT_S)
    assert result.returncode == 0, result.stderr.decode("cp1252", "replace")[-2000:]
    assert b"\\u2192" in result.stdout  # →, escaped
