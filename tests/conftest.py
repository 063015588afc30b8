"""Shared fixtures: where the real training data lives (a shared/data folder beside the repository)."""

import contextlib
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = REPO_ROOT.parent / "shared" / "data"


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The read-only real data folder; tests that need it are skipped when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"shared data not found at {SHARED_DATA}")
    return SHARED_DATA


@pytest.fixture(scope="session")
def tiny_model(tmp_path_factory, shared_data):
    """(training checkpoint, bundle folder) of the ``tiny`` preset trained once per session (~10 s) on
    cuts of the shared ZeroEGGS take; built by tests/models/train_fixtures.py."""
    helpers = str(REPO_ROOT / "tests" / "models")
    if helpers not in sys.path:
        sys.path.insert(0, helpers)
    from train_fixtures import train_tiny_bundle

    return train_tiny_bundle(tmp_path_factory.mktemp("tiny_model"), shared_data / "zeggs")


@pytest.fixture(scope="session")
def tiny_model_full_lookahead(tmp_path_factory, shared_data):
    """The tiny model trained without look-ahead truncation: it serves only --latency quality (δ = δa)."""
    helpers = str(REPO_ROOT / "tests" / "models")
    if helpers not in sys.path:
        sys.path.insert(0, helpers)
    from train_fixtures import train_tiny_bundle

    return train_tiny_bundle(tmp_path_factory.mktemp("tiny_full_lookahead"), shared_data / "zeggs",
                             lookahead_truncation=False)


@pytest.fixture(scope="session", autouse=True)
def shipped_repertoires():
    """The shipped gesture lexicon, encoded once per model bundle (its folder and its files as they are), style label,
    seed and threads for the whole run (what :func:`load_repertoire` gives depends on nothing else, and the lexicon is
    read-only package data): the sessions that many tests build with the default settings would each encode the same
    clips again (about a second of CPU a session). Any other lexicon is loaded as it is asked for. The benchmarks'
    and ``gesturecast eval``'s sessions (tools/eval/generate.py, which keeps them only per bundle object, and every
    command loads its bundle anew) share the same ones."""
    from gesturecast.realtime.run import engine_setup
    from gesturecast.settings import DEFAULT_GESTURES_DIR
    from gesturecast.tools.eval import generate

    load = engine_setup.load_repertoire
    loaded = {}

    def load_shipped_once(settings, bundle):
        if settings.gestures != DEFAULT_GESTURES_DIR:
            return load(settings, bundle)
        files = tuple((path.name, path.stat().st_mtime_ns, path.stat().st_size)
                      for path in sorted(Path(bundle.directory).iterdir()) if path.is_file())
        prompt = settings.style_prompt()
        key = (Path(bundle.directory), files, prompt.value if prompt.kind == "label" else None, settings.seed,
               settings.threads)
        if key not in loaded:
            loaded[key] = load(settings, bundle)
        return loaded[key]

    engine_setup.load_repertoire = generate.load_repertoire = load_shipped_once
    yield
    engine_setup.load_repertoire = generate.load_repertoire = load


RAY_CPUS = 4  # the shared local Ray: a batch's two one-CPU actors, or two Serve replicas and a redeploy's new one


@pytest.fixture(scope="session")
def ray_cluster():
    """The ``ray`` module, connected to one local Ray (loopback, no dashboard) that every Ray test of the run shares,
    started on first use (a Ray start and shutdown cost seconds each); skipped where Ray is not installed
    (``gesturecast[scale]``). Its Serve proxy loads the replica-loss middleware, as under ``serve --ray``."""
    ray = pytest.importorskip("ray", reason="Ray is the optional extra gesturecast[scale]")
    from gesturecast.realtime.serve.ray_proxy import install_proxy_callback

    install_proxy_callback()  # as serve --ray does before it starts a local Ray
    ray.init(num_cpus=RAY_CPUS, include_dashboard=False, logging_level="ERROR")
    try:
        yield ray
    finally:
        ray.shutdown()


@pytest.fixture
def cli_here(capsys, monkeypatch):
    """``gesturecast ARGS`` run by ``gesturecast.cli.main`` in this process (optionally in folder ``cwd``), as a
    CompletedProcess with its exit status and the lines it printed (its log lines go to pytest's log capture): for
    tests where a process boundary is not the point, without an interpreter's start and imports per run."""
    from gesturecast import cli

    def run(*argv: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
        if cwd is not None:
            monkeypatch.chdir(cwd)
        capsys.readouterr()
        try:
            status = cli.main(list(argv))
        except SystemExit as exited:  # argparse ends --help, --version and a usage error so
            status = exited.code
        out, err = capsys.readouterr()
        return subprocess.CompletedProcess(["gesturecast", *argv], status, out, err)

    return run


@pytest.fixture
def virtual_mic():
    """A running private PulseAudio whose default source is a FIFO (tools/bench/virtual_mic.py), torn down
    after the test; skipped with the reason where its Debian packages are missing (`make test` installs them)."""
    from gesturecast.tools.bench.virtual_mic import VirtualMicrophone, missing_requirements

    reason = missing_requirements()
    if reason is not None:
        pytest.skip(reason)
    folder = Path(tempfile.mkdtemp(prefix="gc-mic-"))  # short: the daemon's socket path must fit in 108 bytes
    try:
        with VirtualMicrophone(folder) as mic:
            yield mic
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="session")
def speech_16k(shared_data):
    """(n,) float32: 8 s of real ZeroEGGS speech at 16 kHz."""
    from gesturecast.models.audio.files import SAMPLE_RATE, load_audio

    return load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[: 8 * SAMPLE_RATE]


POLL_S = 0.05  # how often CliProcess looks at the stderr lines collected so far


STOP_SIGNAL_NAMES = ("SIGINT", "SIGTERM", "SIGHUP")  # Ctrl-C, a service manager's stop, a closed terminal


def default_sigint() -> None:
    """In a child before exec: SIGINT, SIGTERM and SIGHUP back to their default dispositions (a suite started
    under ``nohup`` ignores SIGHUP, and children would inherit that)."""
    for name in STOP_SIGNAL_NAMES:
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)


def child_pids(pid: int) -> list[int]:
    """The processes ``pid`` started, and theirs (Linux: /proc), e.g. a process pool's server and workers."""
    children = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            children += [int(child) for child in (task / "children").read_text().split()]
        except OSError:  # the thread or the process ended meanwhile
            continue
    return [grandchild for child in children for grandchild in (child, *child_pids(child))]


def pid_running(pid: int) -> bool:
    """Whether process ``pid`` still runs (an exited one waiting to be reaped, a zombie, does not)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")


class CliProcess:
    """``gesturecast ARGS`` as a real subprocess; stderr lines are collected on a thread as they come."""

    def __init__(self, args: list[str], env: dict[str, str] | None = None) -> None:
        # a suite started as a background job of a non-interactive shell runs with SIGINT ignored; children inherit
        # that (Python then installs no KeyboardInterrupt handler), while a user's shell starts gesturecast with it
        self.process = subprocess.Popen([sys.executable, "-m", "gesturecast.cli", *args], env=env,
                                        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                        preexec_fn=default_sigint)
        self.stderr_lines: list[str] = []
        self._reader = threading.Thread(target=self._read_stderr, daemon=True)
        self._reader.start()
        self._stdout: list[str] = []  # read on a thread too: a process it left running may hold the pipe open
        self._stdout_reader = threading.Thread(target=lambda: self._stdout.extend(self.process.stdout), daemon=True)
        self._stdout_reader.start()

    def _read_stderr(self) -> None:
        for line in self.process.stderr:
            self.stderr_lines.append(line.rstrip("\n"))

    def wait_for_stderr(self, text: str, timeout_s: float, count: int = 1) -> str:
        """The ``count``-th stderr line containing ``text``; fails the test after ``timeout_s``."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            found = [line for line in self.stderr_lines if text in line]
            if len(found) >= count:
                return found[count - 1]
            if self.process.poll() is not None and not self._reader.is_alive():
                break
            time.sleep(POLL_S)
        self.kill()
        pytest.fail(f"no stderr line with {text!r} within {timeout_s} s; stderr: {self.stderr_lines}")

    def interrupt(self, bound_s: float) -> tuple[int, float, str]:
        """Send SIGINT; (exit status, seconds until exit, stdout). Fails if it is still running after ``bound_s``."""
        return self.stop(signal.SIGINT, bound_s)

    def stop(self, signum: int, bound_s: float, with_children: bool = False) -> tuple[int, float, str]:
        """Send ``signum`` (to its child processes too with ``with_children``, as systemd and a closed terminal
        do); (exit status, seconds until exit, stdout). Fails if it is still running after ``bound_s``."""
        children = child_pids(self.process.pid) if with_children else []
        self.process.send_signal(signum)
        for child in children:
            with contextlib.suppress(ProcessLookupError):
                os.kill(child, signum)
        return self.wait(bound_s, since=time.monotonic())

    def wait(self, bound_s: float, since: float | None = None) -> tuple[int, float, str]:
        """(exit status, seconds from ``since`` until exit, stdout); fails if still running after ``bound_s``.
        stdout is what was printed until the pipe closed (or ``bound_s`` after the exit); stderr stays with the
        reader thread."""
        since = time.monotonic() if since is None else since
        try:
            self.process.wait(timeout=bound_s)
        except subprocess.TimeoutExpired:
            self.kill()
            pytest.fail(f"still running {bound_s} s later; stderr: {self.stderr_lines}")
        elapsed = time.monotonic() - since
        self._reader.join(bound_s)
        self._stdout_reader.join(bound_s)
        return self.process.returncode, elapsed, "".join(self._stdout)

    def children(self) -> list[int]:
        """The processes it started, and theirs (Linux), e.g. a process pool's server and workers."""
        return child_pids(self.process.pid)

    @staticmethod
    def still_running(pids: list[int], bound_s: float) -> list[int]:
        """Those of ``pids`` still running after waiting up to ``bound_s`` for them to end."""
        poll_until(lambda: not any(pid_running(pid) for pid in pids), bound_s)
        return [pid for pid in pids if pid_running(pid)]

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
            self.process.wait()


def poll_until(predicate, limit_s: float = 30.0) -> bool:
    """Poll ``predicate`` until it holds or ``limit_s`` passes (a bound on hanging, not a speed assertion)."""
    deadline = time.monotonic() + limit_s
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.01)
    return predicate()


@pytest.fixture
def wait_until():
    """:func:`poll_until`, for tests that wait on another thread (a server recording a closed stream)."""
    return poll_until


@pytest.fixture
def cli_process():
    """Start ``gesturecast`` subprocesses (CliProcess); any still running at teardown are killed."""
    started: list[CliProcess] = []

    def start(args: list[str], env: dict[str, str] | None = None) -> CliProcess:
        started.append(CliProcess(args, env))
        return started[-1]

    yield start
    for process in started:
        process.kill()
