"""Atomic output files: umask modes, non-regular targets refused, a failed write keeps the old file,
outputs that alias inputs refused (real files, FIFOs, symlinks and a size-limited subprocess)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from gesturecast.errors import UserError
from gesturecast.files import check_distinct, write_text_atomic

SIZE_LIMIT_BYTES = 1000  # RLIMIT_FSIZE for the subprocess: a larger write fails with EFBIG, also as root

# writes a text larger than the size limit to argv[1] with a file size limit set; SIGXFSZ ignored -> EFBIG
LIMITED_WRITE = f"""
import resource, signal, sys
from gesturecast.errors import UserError
from gesturecast.files import write_text_atomic
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, ({SIZE_LIMIT_BYTES}, {SIZE_LIMIT_BYTES}))
try:
    write_text_atomic(sys.argv[1], "x" * {4 * SIZE_LIMIT_BYTES})
except UserError as error:
    sys.exit(f"error: {{error}}")
"""


@pytest.fixture
def umask_022():
    previous = os.umask(0o022)
    yield
    os.umask(previous)


def test_new_files_get_the_umask_mode(tmp_path, umask_022):
    target = tmp_path / "out.json"
    write_text_atomic(target, "{}\n")
    assert target.read_text() == "{}\n"
    assert oct(target.stat().st_mode & 0o777) == oct(0o644)
    assert [p.name for p in tmp_path.iterdir()] == ["out.json"]  # no temporary file left


def test_a_fifo_target_is_refused_and_stays_a_fifo(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(UserError, match="not a regular file"):
        write_text_atomic(fifo, "data")
    assert fifo.is_fifo() and sorted(tmp_path.iterdir()) == [fifo]


def test_a_folder_target_is_refused(tmp_path):
    with pytest.raises(UserError, match="is a folder"):
        write_text_atomic(tmp_path, "data")


def test_a_symlink_target_replaces_the_file_it_points_to(tmp_path):
    real = tmp_path / "real.txt"
    real.write_text("old")
    link = tmp_path / "link.txt"
    link.symlink_to(real)
    write_text_atomic(link, "new")
    assert link.is_symlink() and real.read_text() == "new"


def test_a_failed_write_keeps_the_old_file_and_says_so_in_one_line(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("the old content")
    result = subprocess.run([sys.executable, "-c", LIMITED_WRITE, str(target)], capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 1
    assert result.stderr.strip().splitlines() == [f"error: cannot write {target}: File too large"]
    assert target.read_text() == "the old content"
    assert sorted(tmp_path.iterdir()) == [target]


def test_an_output_that_is_an_input_or_another_output_is_refused(tmp_path):
    audio = tmp_path / "take.wav"
    audio.write_bytes(b"RIFF")
    link = tmp_path / "link.wav"
    link.symlink_to(audio)
    with pytest.raises(UserError, match="--bvh .* is the same file as --input"):
        check_distinct([("--input", audio)], [("--bvh", link)])
    with pytest.raises(UserError, match="--json .* is the same file as -o"):
        check_distinct([("audio", audio)], [("-o", tmp_path / "a.bvh"), ("--json", tmp_path / "." / "a.bvh")])
    check_distinct([("audio", audio)], [("-o", tmp_path / "a.bvh"), ("--json", None)])  # distinct: accepted
