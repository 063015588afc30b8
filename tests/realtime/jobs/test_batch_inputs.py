"""``generate --batch``: a malformed CSV is one line naming the CSV and its line, and audio files that are not
there fail at once without reaching a worker (no model training: the bundled model, a recording runner)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from gesturecast.cli import main
from gesturecast.errors import UserError
from gesturecast.realtime.jobs import batch_cli
from gesturecast.realtime.jobs.batch import BATCH_FAILED_EXIT, SUMMARY_NAME, JobResult
from gesturecast.realtime.jobs.batch_jobs import find_jobs

REPO_ROOT = Path(__file__).resolve().parents[3]
SAMPLE_SPEECH = REPO_ROOT / "gesturecast" / "samples" / "sample_speech.wav"
MISSING_ROWS = 300


@pytest.mark.parametrize(("table", "message"), [
    ("path\n.\n", "line 2: 'path' . names a folder, not an audio file"),  # was an IndexError
    ("path\na.wav\nsub/..\n", "line 3: 'path' sub/.. names a folder"),
    ("path,style\na.wav,happy,old\n", "line 2: 3 cells, the header has 2 columns"),  # was a TypeError
    ("path,style\na.wav,happy\n\nb.wav,happy,old,x\n", "line 4: 4 cells, the header has 2 columns"),  # was ignored
    ("path,style,seed,style\na.wav,happy,1,old\n", "line 1: column(s) style appear more than once"),  # was ignored
    ("path,mood\na.wav,happy\n", "line 1: unknown column(s) mood"),
])
def test_malformed_csv_is_one_line_naming_the_csv_and_the_line(tmp_path: Path, table: str, message: str):
    (tmp_path / "lines.csv").write_text(table)
    with pytest.raises(UserError) as error:
        find_jobs(tmp_path / "lines.csv", tmp_path / "out", with_json=False)
    assert str(error.value).startswith(f"--batch {tmp_path / 'lines.csv'} ") and message in str(error.value)
    assert "\n" not in str(error.value)


def test_missing_audio_files_fail_without_reaching_a_worker(tmp_path: Path, monkeypatch, capsys):
    """Hundreds of missing rows and a folder are failures in the summary; the runner is given only the real file."""
    shutil.copy(SAMPLE_SPEECH, tmp_path / "real.wav")
    (tmp_path / "folder.wav").mkdir()
    rows = ["real.wav", "folder.wav", *(f"missing_{i}.wav" for i in range(MISSING_ROWS))]
    (tmp_path / "lines.csv").write_text("path\n" + "\n".join(rows) + "\n")
    seen: list[Path] = []

    def recording_runner(jobs, base, workers, on_result) -> None:
        for job in jobs:
            seen.append(job.audio)
            on_result(JobResult(str(job.audio), 1.0))

    monkeypatch.setattr(batch_cli, "run_with_processes", recording_runner)
    out = tmp_path / "out"
    code = main(["generate", "--batch", str(tmp_path / "lines.csv"), "-o", str(out), "--workers", "4"])
    assert code == BATCH_FAILED_EXIT, capsys.readouterr().err[-2000:]
    assert seen == [tmp_path / "real.wav"]
    summary = json.loads((out / SUMMARY_NAME).read_text())
    assert (summary["files"], summary["generated"], summary["failed"]) == (len(rows), 1, len(rows) - 1)
    reasons = {Path(failure["path"]).name: failure["error"] for failure in summary["failures"]}
    assert reasons["folder.wav"].endswith("not a regular file (a folder or a device), not an audio file")
    assert reasons["missing_7.wav"] == f"{tmp_path / 'missing_7.wav'}: no such audio file"
    assert summary["workers"] == 1  # as many as files to run, not as asked
