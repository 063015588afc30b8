"""A virtual microphone for tests and benchmarks on machines without a sound card.

A private user-mode PulseAudio (``pulseaudio -n -F``: no default modules, our script only) runs in a
temporary folder; its default source is a ``module-pipe-source`` (16 kHz s16le mono) read from a
FIFO. PortAudio reaches it through ALSA's pulse plugin (Debian ``libasound2-plugins``) as the
devices ``pulse`` and ``default``. :class:`VirtualMicrophone` starts and stops the daemon, gives
the environment a process needs to see it (PortAudio enumerates devices at ``Pa_Initialize``, so
start the program under test as a subprocess with :attr:`VirtualMicrophone.env`), and feeds
speech at real-time pace (:class:`PacedFeeder`), which can be paused (a stalled device) or cut off
by unloading the source (a vanished device).

    python -m gesturecast.tools.bench.virtual_mic SPEECH.wav -- gesturecast bench latency --device pulse

runs the command with the virtual microphone as its only input device, fed with SPEECH.wav on a loop.
"""

from __future__ import annotations

import argparse
import glob
import logging
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

import numpy as np

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio

logger = logging.getLogger(__name__)

SOURCE_NAME = "gesturecast_virtual_mic"
DEVICE_NAME = "pulse"  # the PortAudio (ALSA) input device that reaches the PulseAudio default source
START_TIMEOUT_S = 10.0  # longest wait for the daemon to answer
STOP_TIMEOUT_S = 5.0  # longest wait for the daemon to exit after SIGTERM
POLL_INTERVAL_S = 0.05
FEED_BLOCK_S = 0.02  # the feeder writes this much audio per write (20 ms), each when it is due
PCM16_FULL_SCALE = 32767
PULSE_PLUGIN_GLOB = "/usr/lib/*/alsa-lib/libasound_module_pcm_pulse.so"
REQUIRED_PROGRAMS = ("pulseaudio", "pactl")
DEBIAN_PACKAGES = "pulseaudio pulseaudio-utils libasound2-plugins"
DAEMON_SCRIPT = """.fail
load-module module-native-protocol-unix socket={socket}
load-module module-pipe-source source_name={source} file={fifo} format=s16le rate={rate} channels=1
set-default-source {source}
"""


def missing_requirements() -> str | None:
    """Why a virtual microphone cannot run here (a sentence naming the Debian packages), or None."""
    absent = [name for name in REQUIRED_PROGRAMS if shutil.which(name) is None]
    if not glob.glob(PULSE_PLUGIN_GLOB):
        absent.append("ALSA pulse plugin")
    if not absent:
        return None
    return f"virtual microphone needs {', '.join(absent)}: install the Debian packages {DEBIAN_PACKAGES}"


def to_pcm16(samples: np.ndarray) -> bytes:
    """(n,) float32 in [-1, 1] → little-endian s16 bytes, the pipe source's format."""
    return (np.clip(samples, -1.0, 1.0) * PCM16_FULL_SCALE).astype("<i2").tobytes()


class PacedFeeder:
    """Writes audio into the FIFO at real-time pace on its own thread; pausable, stoppable."""

    def __init__(self, fifo: Path, samples: np.ndarray, loop: bool = False) -> None:
        self.fifo = fifo
        self.samples = samples  # (n,) float32, 16 kHz
        self.loop = loop
        self.written_samples = 0
        self._running = threading.Event()
        self._running.set()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="virtual-mic-feed", daemon=True)

    def start(self) -> PacedFeeder:
        self._thread.start()
        return self

    def pause(self) -> None:
        """Stop writing (the device stalls: PulseAudio's source delivers no samples)."""
        self._running.clear()

    def resume(self) -> None:
        self._running.set()

    def stop(self) -> None:
        self._stop.set()
        self._running.set()
        self._thread.join(STOP_TIMEOUT_S)

    @property
    def finished(self) -> bool:
        return not self._thread.is_alive()

    def _blocks(self) -> Iterator[np.ndarray]:
        """(FEED_BLOCK_S * 16000,) float32 blocks of the samples (the last may be shorter), once or forever."""
        step = int(FEED_BLOCK_S * SAMPLE_RATE)
        while True:
            for start in range(0, self.samples.shape[0], step):
                yield self.samples[start : start + step]
            if not self.loop:
                return

    def _run(self) -> None:
        with self.fifo.open("wb", buffering=0) as pipe:
            due = time.monotonic()
            for block in self._blocks():
                if self._stop.is_set():
                    return
                if not self._running.is_set():
                    self._running.wait()
                    if self._stop.is_set():
                        return
                    due = time.monotonic()
                self._write(pipe, block)
                due += block.shape[0] / SAMPLE_RATE
                time.sleep(max(0.0, due - time.monotonic()))

    def _write(self, pipe: BinaryIO, block: np.ndarray) -> None:
        try:
            pipe.write(to_pcm16(block))
        except BrokenPipeError:  # the source was unloaded: nobody reads any more
            self._stop.set()
            return
        self.written_samples += block.shape[0]


class VirtualMicrophone:
    """A private PulseAudio with a pipe source in ``folder``; a context manager that always tears down."""

    def __init__(self, folder: Path) -> None:
        self.folder = Path(folder)
        self.runtime = self.folder / "runtime"
        self.home = self.folder / "home"
        self.fifo = self.folder / "mic.fifo"
        self.socket = self.runtime / "native"
        self.log_path = self.folder / "pulseaudio.log"
        self._daemon: subprocess.Popen | None = None

    @property
    def env(self) -> dict[str, str]:
        """This process's environment pointed at the private daemon (for subprocesses under test)."""
        return {**os.environ, "XDG_RUNTIME_DIR": str(self.runtime), "PULSE_RUNTIME_PATH": str(self.runtime),
                "HOME": str(self.home), "PULSE_SERVER": f"unix:{self.socket}"}

    def start(self) -> VirtualMicrophone:
        """Start the daemon and wait (bounded) until it answers and the FIFO exists."""
        reason = missing_requirements()
        if reason is not None:
            raise UserError(reason)
        self.runtime.mkdir(mode=0o700, parents=True, exist_ok=True)
        self.home.mkdir(parents=True, exist_ok=True)
        script = self.folder / "daemon.pa"
        script.write_text(DAEMON_SCRIPT.format(socket=self.socket, source=SOURCE_NAME, fifo=self.fifo,
                                               rate=SAMPLE_RATE))
        with self.log_path.open("wb") as log:
            self._daemon = subprocess.Popen(
                ["pulseaudio", "--daemonize=no", "--exit-idle-time=-1", "-n", "-F", str(script),
                 "--log-target=stderr"], stdout=log, stderr=subprocess.STDOUT, env=self.env)
        self._wait_until_ready()
        return self

    def _wait_until_ready(self) -> None:
        deadline = time.monotonic() + START_TIMEOUT_S
        while time.monotonic() < deadline:
            if self._daemon.poll() is not None:
                raise UserError(f"pulseaudio exited at start: {self.log_path.read_text().strip()[-500:]}")
            if self.fifo.exists() and self.pactl("info").returncode == 0:
                return
            time.sleep(POLL_INTERVAL_S)
        self.close()
        raise UserError(f"pulseaudio did not answer within {START_TIMEOUT_S:.0f} s (log: {self.log_path})")

    def pactl(self, *arguments: str) -> subprocess.CompletedProcess:
        return subprocess.run(["pactl", *arguments], env=self.env, capture_output=True, text=True,
                              timeout=START_TIMEOUT_S)

    def feed(self, samples: np.ndarray, loop: bool = False) -> PacedFeeder:
        """Start writing (n,) float32 16 kHz samples at real-time pace."""
        return PacedFeeder(self.fifo, samples, loop).start()

    def unload_source(self) -> None:
        """Remove the pipe source from the daemon, as when a USB microphone is unplugged."""
        modules = self.pactl("list", "short", "modules").stdout.splitlines()
        index = next(line.split()[0] for line in modules if "module-pipe-source" in line)
        self.pactl("unload-module", index)

    def close(self) -> None:
        """Stop the daemon (SIGTERM, then SIGKILL after a bound)."""
        if self._daemon is None or self._daemon.poll() is not None:
            return
        self._daemon.terminate()
        try:
            self._daemon.wait(STOP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            self._daemon.kill()
            self._daemon.wait()

    def __enter__(self) -> VirtualMicrophone:
        return self.start()

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def main(argv: list[str] | None = None) -> int:
    """``python -m gesturecast.tools.bench.virtual_mic SPEECH -- COMMAND...``: run COMMAND with the mic fed."""
    parser = argparse.ArgumentParser(prog="virtual_mic", description=__doc__.splitlines()[0])
    parser.add_argument("speech", type=Path, help="audio file fed to the virtual microphone on a loop")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- then the command to run")
    args = parser.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("give the command to run after --")
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    try:
        speech = load_audio(args.speech)
        with tempfile.TemporaryDirectory() as folder, VirtualMicrophone(Path(folder)) as mic:
            feeder = mic.feed(speech, loop=True)
            try:
                return subprocess.run(command, env=mic.env).returncode
            finally:
                feeder.stop()
    except UserError as error:
        sys.stderr.write(f"virtual_mic: error: {error}\n")
        return 2


if __name__ == "__main__":
    sys.exit(main())
