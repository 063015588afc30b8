"""The fenced code blocks of README.md and docs/*.md, and the folder they run in (tests/test_docs_examples.py).

Every fence carries a language: ``python`` and ``bash`` blocks run; ``text`` (program output, diagrams, command
synopses), ``json`` and ``yaml`` blocks are data. A block that cannot run here is preceded by one line
``<!-- not run: REASON -->`` naming what it needs (a microphone, the network, several machines).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import socket
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import soundfile

REPO_ROOT = Path(__file__).resolve().parents[1]
PAGES = ("README.md", *sorted(f"docs/{page.name}" for page in (REPO_ROOT / "docs").glob("*.md")))
FENCE = re.compile(r"^(?:<!-- not run: (?P<skip>[^>]*) -->\n)?```(?P<language>\S*)\n(?P<code>.*?)^```$", re.S | re.M)
RUNNABLE = ("python", "bash")
DATA_LANGUAGES = ("text", "json", "yaml")
SECONDS = 3  # of speech in talk.wav
RATE = 44100  # talk.wav's rate: a user's recording, not the model's 16 kHz

# The shell the bash blocks run in. The commands are the real ones; the few that would run for minutes or until
# stopped get a small input: `live` reads talk.wav as fast as possible instead of a microphone, `serve` is stopped
# (SIGINT, as Ctrl-C) once it prints where streams go and must then end as after Ctrl-C (status 130; a server still
# running a minute later is killed and fails), training and data builds use a few takes and steps. `serve` runs in
# the background with SIGINT at its default (a background job of a script would ignore it).
BASH_PRELUDE = """set -eo pipefail
until_gone() {  # poll up to 60 s while process $1 runs and command $2 fails
  for _ in $(seq 600); do kill -0 "$1" 2>/dev/null && ! eval "$2" || return 0; sleep 0.1; done
}
serve_until_ready() {
  local out status=0 pid; out=$(mktemp)
  env --default-signal=INT gesturecast "$@" > "$out" & pid=$!
  until_gone "$pid" 'grep -q "Ctrl-C stops" "$out"'
  kill -INT "$pid" 2>/dev/null || true
  until_gone "$pid" false
  kill -KILL "$pid" 2>/dev/null || true
  wait "$pid" || status=$?
  cat "$out"; rm -f "$out"; [ "$status" = 130 ]
}
gesturecast() {
  case "$1 $2" in
    "live "*) command gesturecast "$@" --input talk.wav --pace fast ;;
    "serve "*) serve_until_ready "$@" ;;
    "train "*) command gesturecast "$@" --preset tiny --vq-steps 2 --denoiser-steps 2 --prompt-steps 2 \\
                 --no-progress ;;
    "data build") command gesturecast "$@" --limit 1 ;;
    "gestures build") command gesturecast "$@" --per-style 1 --styles 1 ;;
    "bench styles") command gesturecast "$@" --quick ;;
    "bench face") command gesturecast "$@" --minutes 0.2 ;;
    *) command gesturecast "$@" ;;
  esac
}
"""
LISTEN_PORTS = ("8765", "8766", "9001")  # ports the blocks listen on: each run gets free ones instead


@dataclass(frozen=True)
class Block:
    """One fenced block: where it is, its language, its text, and why it is not run (None: it runs)."""

    page: str
    line: int
    language: str
    code: str
    skip: str | None

    @property
    def name(self) -> str:
        return f"{self.page}:{self.line}"

    @property
    def needs_data(self) -> bool:
        """It reads the training data (DATA, the SMPL-X take copied from it) or the cache built from it."""
        return any(word in self.code for word in ("DATA", ".npz", "--cache"))

    @property
    def needs_microphone(self) -> bool:
        return "gesturecast devices" in self.code

    @property
    def runs(self) -> tuple[str, str]:
        """What running the block does: its language and its lines without comments or repeated spaces (the same
        commands written on two pages, commented differently, run the same)."""
        lines = (" ".join(line.split(" # ", 1)[0].split()) for line in self.code.splitlines())
        return self.language, "\n".join(line for line in lines if line)


def page_blocks(page: str) -> list[Block]:
    """The fenced blocks of one page, in order."""
    text = (REPO_ROOT / page).read_text(encoding="utf-8")
    return [Block(page, text.count("\n", 0, match.start("language")) + 1, match["language"], match["code"],
                  match["skip"]) for match in FENCE.finditer(text)]


def all_blocks() -> list[Block]:
    return [block for page in PAGES for block in page_blocks(page)]


def distinct_runs(blocks: list[Block]) -> list[Block]:
    """The first block of each distinct run (:attr:`Block.runs`): a command repeated on several pages runs once."""
    first: dict[tuple[str, str], Block] = {}
    for block in blocks:
        first.setdefault(block.runs, block)
    return list(first.values())


def fence_count(page: str) -> int:
    """Lines opening or closing a fence: twice the blocks when every fence parsed."""
    return sum(line.startswith("```") for line in (REPO_ROOT / page).read_text(encoding="utf-8").splitlines())


GROUP_COMMANDS = ("bench", "data", "gestures")  # commands whose next word is a sub-command
COMMAND_LINE = re.compile(r"gesturecast [a-z-]+(?: |$)")  # a command, not output such as "gesturecast live: error"


def command_lines(code: str) -> list[str]:
    """The ``gesturecast ...`` lines of a block without their comments, continuations joined (a line after a
    trailing backslash, or an indented line under a command)."""
    commands: list[str] = []
    current = False
    for line in code.splitlines():
        continues = current and (line.startswith(" ") or commands[-1].endswith("\\"))
        starts = COMMAND_LINE.match(line) is not None
        if starts or continues:
            text = line.split(" # ", 1)[0].strip()
            commands.append(f"{commands.pop()} {text}" if continues else text)
        current = starts or continues
    return commands


def command_words(line: str) -> list[str]:
    """The sub-command of a ``gesturecast`` line: ``["generate"]``, or ``["bench", "voices"]`` for a group."""
    words = line.split()[1:3]
    return words[:2] if words[0] in GROUP_COMMANDS else words[:1]


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def with_free_ports(code: str) -> str:
    """The block with each listening port replaced by a free one (other programs may hold the documented ones)."""
    for port in LISTEN_PORTS:
        code = re.sub(rf"\b{port}\b", str(free_port()), code)
    return code


def bash_script(code: str) -> str:
    return BASH_PRELUDE + with_free_ports(code)


def build_folder(folder: Path, shared_data: Path | None) -> Path:
    """The files the blocks name: talk.wav (3 s, 44.1 kHz stereo; half its length is no multiple of 1600 samples, as
    in the recordings the README's first streaming example failed on), its words, a folder and a CSV of voice lines,
    BVHs of generated motion, a VRM avatar, the examples, and DATA (the shared training data) where it exists."""
    import gesturecast
    from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio

    speech = load_audio(PACKAGED_SAMPLE)[: SECONDS * SAMPLE_RATE]
    stereo = np.repeat(np.interp(np.arange(SECONDS * RATE) * SAMPLE_RATE / RATE, np.arange(speech.shape[0]),
                                 speech)[:, None], 2, axis=1).astype(np.float32)  # (n, 2)
    for name in ("talk.wav", "speech.wav", "speech8.wav"):
        soundfile.write(folder / name, stereo, RATE)
    (folder / "voice_lines").mkdir()
    for index in range(2):
        soundfile.write(folder / "voice_lines" / f"line{index}.wav", speech[index * SAMPLE_RATE:][:SAMPLE_RATE],
                        SAMPLE_RATE)
    (folder / "lines.csv").write_text("path,style\nvoice_lines/line0.wav,happy\nvoice_lines/line1.wav,old\n")
    words = [{"word": "hello", "start": 0.4, "end": 0.8}, {"word": "everyone", "start": 0.8, "end": 1.4}]
    (folder / "words.json").write_text(json.dumps(words))
    motion = gesturecast.generate(PACKAGED_SAMPLE, seed=0)  # 25 s: long enough for --start 10 --seconds 5
    for name in ("IN.bvh", "take.bvh", "real.bvh", "gen.bvh"):
        motion.save(folder / name)
    shutil.copy(REPO_ROOT / "bridges" / "viewer" / "avatar" / "cryptovoxels.vrm", folder / "my_avatar.vrm")
    (folder / "examples").symlink_to(REPO_ROOT / "examples")
    if shared_data is not None:
        (folder / "DATA").symlink_to(shared_data)
        shutil.copy(shared_data / "beat2" / "2_scott_0_1_1.npz", folder / "IN.npz")
    return folder


def shared_data_folder() -> Path | None:
    """The training data folder (``$GESTURECAST_SHARED_DATA``, else shared/data beside the repository), or None."""
    folder = Path(os.environ.get("GESTURECAST_SHARED_DATA", REPO_ROOT.parent / "shared" / "data"))
    return folder if folder.is_dir() else None
