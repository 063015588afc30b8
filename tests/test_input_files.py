"""User-given input files are read with a size bound: at most the limit and one byte, whatever the path names."""

from __future__ import annotations

from pathlib import Path

import pytest

from gesturecast.errors import UserError
from gesturecast.input_files import format_size, read_bounded

DEV_ZERO = Path("/dev/zero")


def test_a_file_up_to_the_limit_is_read_whole_and_one_byte_more_is_refused(tmp_path):
    path = tmp_path / "data"
    path.write_bytes(b"x" * 100)
    assert read_bounded(path, 100, "the test file") == b"x" * 100
    with pytest.raises(UserError, match=f"the test file {path} holds more than 99 bytes"):
        read_bounded(path, 99, "the test file")


def test_a_missing_file_or_a_folder_is_one_line(tmp_path):
    with pytest.raises(UserError, match=f"cannot read the test file {tmp_path / 'nope'}: No such file"):
        read_bounded(tmp_path / "nope", 10, "the test file")
    with pytest.raises(UserError, match="cannot read the test file"):
        read_bounded(tmp_path, 10, "the test file")


@pytest.mark.skipif(not DEV_ZERO.exists(), reason="no /dev/zero on this system")
def test_a_device_that_never_ends_is_refused_after_the_limit(tmp_path):
    with pytest.raises(UserError, match="holds more than 4 KiB"):
        read_bounded(DEV_ZERO, 4096, "the test file")


def test_sizes_are_written_as_people_read_them():
    assert [format_size(n) for n in (100, 4096, 1 << 20, 64 << 20, 1 << 30)] == [
        "100 bytes", "4 KiB", "1 MiB", "64 MiB", "1024 MiB"]


def test_a_model_manifest_above_its_bound_is_refused(monkeypatch):
    """``--model DIR``: model.json is read with a bound (64 MiB; here lowered below the bundled one's size)."""
    from gesturecast.models.runtime import bundle
    from gesturecast.settings import DEFAULT_MODEL_DIR

    monkeypatch.setattr(bundle, "MAX_MANIFEST_BYTES", 1000)
    with pytest.raises(UserError, match="model manifest .*model.json holds more than 1000 bytes"):
        bundle.read_manifest(DEFAULT_MODEL_DIR)


def test_a_batch_csv_above_its_bound_is_refused(tmp_path, monkeypatch):
    """``generate --batch TABLE.csv``: the table is read with a bound (64 MiB; here lowered to 100 bytes)."""
    from gesturecast.realtime.jobs import batch_jobs

    table = tmp_path / "lines.csv"
    table.write_text("path\n" + "".join(f"line_{i}.wav\n" for i in range(20)))
    monkeypatch.setattr(batch_jobs, "MAX_CSV_BYTES", 100)
    with pytest.raises(UserError, match=f"--batch CSV {table} holds more than 100 bytes"):
        batch_jobs.find_jobs(table, tmp_path / "out", with_json=False)
