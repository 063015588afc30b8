"""`generate --batch`: a folder or CSV of audio files → BVH/JSON per file on worker processes (and Ray Data),
the same bytes as `generate FILE`, resumable, a bad file listed in the summary without stopping the rest."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import soundfile

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.models.motion.bvh import read_bvh
from gesturecast.realtime.jobs.batch import BATCH_FAILED_EXIT, SUMMARY_NAME
from gesturecast.realtime.jobs.batch_jobs import find_jobs

CLIP_SECONDS = 1.0
STEREO_RATE = 44100  # a second file format: stereo 44.1 kHz float, resampled by the reader
CLI_TIMEOUT_S = 300


@pytest.fixture(scope="module")
def clips(tmp_path_factory, shared_data) -> Path:
    """A folder: two 1 s speech clips (one 16 kHz int16, one 44.1 kHz stereo in a sub-folder), an empty WAV
    and a text file named .wav."""
    folder = tmp_path_factory.mktemp("batch_in")
    speech = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")  # (n,)
    n = int(CLIP_SECONDS * SAMPLE_RATE)
    soundfile.write(folder / "a.wav", speech[:n], SAMPLE_RATE, subtype="PCM_16")
    (folder / "sub").mkdir()
    other = load_audio(shared_data / "speech" / "tts_03_en-gb.wav")[:n]
    stereo = np.interp(np.arange(int(CLIP_SECONDS * STEREO_RATE)) * SAMPLE_RATE / STEREO_RATE, np.arange(n), other)
    soundfile.write(folder / "sub" / "b.wav", np.stack([stereo, stereo], axis=1), STEREO_RATE, subtype="FLOAT")
    (folder / "empty.wav").write_bytes(b"")
    (folder / "corrupt.wav").write_text("not audio at all\n")
    return folder


def run_cli(*argv: str, prelude: str = "") -> subprocess.CompletedProcess:
    code = f"{prelude}import sys; from gesturecast.cli import main; sys.exit(main(sys.argv[1:]))"
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    return subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=CLI_TIMEOUT_S,
                          env=env)


def read_summary(folder: Path) -> dict:
    return json.loads((folder / SUMMARY_NAME).read_text())


def test_a_folder_batch_writes_what_generate_writes_lists_bad_files_and_resumes(tiny_model, clips, tmp_path, cli_here):
    out = tmp_path / "out"
    model = ["--model", str(tiny_model[1])]
    result = run_cli("generate", "--batch", str(clips), "-o", str(out), "--with-json", "--with-vrma", "--workers", "2",
                     *model)
    assert result.returncode == BATCH_FAILED_EXIT, result.stderr[-3000:]
    summary = read_summary(out)
    assert (summary["files"], summary["generated"], summary["skipped"], summary["failed"]) == (4, 2, 0, 2)
    assert summary["runner"] == "processes" and summary["workers"] == 2
    assert summary["audio_seconds"] == pytest.approx(2 * CLIP_SECONDS, abs=1e-3)
    reasons = {Path(f["path"]).name: f["error"] for f in summary["failures"]}
    assert "the file is empty" in reasons["empty.wav"] and "not a readable audio file" in reasons["corrupt.wav"]
    assert "failed: " in result.stderr and "4 files: 2 generated" in result.stdout

    single = tmp_path / "single"
    for audio, name in ((clips / "a.wav", "a"), (clips / "sub" / "b.wav", "sub/b")):
        assert cli_here("generate", str(audio), "-o", f"{single}/{name}.bvh", "--json", f"{single}/{name}.json",
                        "--vrma", f"{single}/{name}.vrma", *model).returncode == 0
        for suffix in (".bvh", ".json", ".vrma"):
            assert (out / f"{name}{suffix}").read_bytes() == (single / f"{name}{suffix}").read_bytes()

    finished = {p: p.stat().st_mtime_ns for p in out.rglob("*.bvh")}
    again = run_cli("generate", "--batch", str(clips), "-o", str(out), "--with-json", "--workers", "2", *model)
    assert again.returncode == BATCH_FAILED_EXIT
    assert (read_summary(out)["skipped"], read_summary(out)["generated"], read_summary(out)["failed"]) == (2, 0, 2)
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*.bvh")} == finished


def test_csv_rows_set_each_file_s_style_and_seed(tiny_model, clips, tmp_path, cli_here):
    table = tmp_path / "lines.csv"
    (tmp_path / "x.wav").symlink_to(clips / "a.wav")
    (tmp_path / "y.wav").symlink_to(clips / "a.wav")
    table.write_text(f"path,style,seed,part_style\n{clips / 'a.wav'},old,3,arms=happy legs=neutral\nx.wav,,,\n"
                     "y.wav,,,\n")
    out = tmp_path / "out"
    model = ["--model", str(tiny_model[1])]
    result = run_cli("generate", "--batch", str(table), "-o", str(out), "--workers", "1", "--style", "neutral", *model)
    assert result.returncode == 0, result.stderr[-3000:]
    assert read_summary(out)["generated"] == 3
    styled = tmp_path / "styled.bvh"
    plain = tmp_path / "plain.bvh"
    assert cli_here("generate", str(clips / "a.wav"), "-o", str(styled), "--style", "old", "--seed", "3",
                    "--part-style", "arms=happy", "legs=neutral", *model).returncode == 0
    assert cli_here("generate", str(clips / "a.wav"), "-o", str(plain), "--style", "neutral", *model).returncode == 0
    assert (out / "a.bvh").read_bytes() == styled.read_bytes()  # outside the CSV's folder: named by the file
    assert (out / "x.bvh").read_bytes() == plain.read_bytes()  # empty cells: the command's flags
    assert (out / "y.bvh").read_bytes() == plain.read_bytes()  # x's session, reset, writes what a new one writes
    assert styled.read_bytes() != plain.read_bytes()


def test_a_csv_transcript_column_cues_gestures_as_generate_transcript_does(tiny_model, clips, tmp_path, cli_here):
    words = tmp_path / "a.words.json"
    words.write_text(json.dumps([{"word": "Hello", "start": 0.5, "end": 0.8}]))
    (tmp_path / "b.wav").symlink_to(clips / "a.wav")
    table = tmp_path / "lines.csv"
    table.write_text(f"path,transcript\n{clips / 'a.wav'},a.words.json\nb.wav,missing.json\n")
    model = ["--model", str(tiny_model[1])]
    result = run_cli("generate", "--batch", str(table), "-o", str(tmp_path / "out"), "--with-json", "--workers", "1",
                     *model)
    assert result.returncode == BATCH_FAILED_EXIT, result.stderr[-3000:]
    (failure,) = read_summary(tmp_path / "out")["failures"]
    assert Path(failure["path"]).name == "b.wav" and "cannot read the transcript" in failure["error"]
    assert "missing.json" in failure["error"]
    single = tmp_path / "single"
    assert cli_here("generate", str(clips / "a.wav"), "-o", f"{single}.bvh", "--json", f"{single}.json",
                    "--transcript", str(words), *model).returncode == 0
    assert (tmp_path / "out" / "a.json").read_bytes() == Path(f"{single}.json").read_bytes()
    assert '"gesture": "wave"' in Path(f"{single}.json").read_text()


@pytest.mark.parametrize(("table", "extra", "message"), [
    ("path,mood\na.wav,happy\n", [], "unknown column(s) mood"),
    ("path,seed\na.wav,-1\n", [], "line 2: column seed must be an integer from 0 to 4294967295"),
    ("file\na.wav\n", [], "needs a header row with a 'path' column"),
    ("path\na.wav\nsub/../a.wav\n", [], "would both write"),
    ("path\na.wav\n", ["--json", "x.json"], "use --with-json"),
    ("path\na.wav\n", ["--vrma", "x.vrma"], "use --with-vrma"),
    ("path\na.wav\n", ["a.wav"], "not both"),
])
def test_bad_batch_input_is_one_line_before_any_work(tiny_model, tmp_path, table, extra, message, cli_here):
    (tmp_path / "sub").mkdir()
    (tmp_path / "lines.csv").write_text(table)
    result = cli_here("generate", "--batch", str(tmp_path / "lines.csv"), "-o", str(tmp_path / "out"), *extra,
                      "--model", str(tiny_model[1]))
    lines = [line for line in result.stderr.splitlines() if not line.startswith(("INFO", "WARNING"))]
    assert result.returncode == 2 and len(lines) == 1, result.stderr[-2000:]
    assert lines[0].startswith("gesturecast generate: error: ") and message in lines[0], lines
    assert not (tmp_path / "out").exists()


def test_a_folder_s_jobs_mirror_its_tree_and_a_missing_source_is_refused(tmp_path):
    (tmp_path / "in" / "deep").mkdir(parents=True)
    for name in ("b.WAV", "deep/a.flac", "notes.txt"):
        (tmp_path / "in" / name).write_bytes(b"")
    jobs = find_jobs(tmp_path / "in", tmp_path / "out", with_json=True)
    assert [(j.audio.relative_to(tmp_path), j.bvh.relative_to(tmp_path), j.json.relative_to(tmp_path))
            for j in jobs] == [(Path("in/b.WAV"), Path("out/b.bvh"), Path("out/b.json")),
                               (Path("in/deep/a.flac"), Path("out/deep/a.bvh"), Path("out/deep/a.json"))]
    with_vrma = find_jobs(tmp_path / "in", tmp_path / "out", with_json=False, with_vrma=True)
    assert [j.motion_paths() for j in with_vrma] == [[tmp_path / "out/b.bvh", tmp_path / "out/b.vrma"],
                                                     [tmp_path / "out/deep/a.bvh", tmp_path / "out/deep/a.vrma"]]
    with pytest.raises(UserError, match="no such folder or CSV"):
        find_jobs(tmp_path / "missing", tmp_path / "out", with_json=False)
    (tmp_path / "nothing").mkdir()
    with pytest.raises(UserError, match="no audio files"):
        find_jobs(tmp_path / "nothing", tmp_path / "out", with_json=False)


def test_ray_runs_the_same_jobs_with_the_same_bytes(tiny_model, clips, tmp_path, cli_here, ray_cluster, monkeypatch):
    """On the run's shared local Ray (tests/conftest.py): the batch's own start of a local Ray and its shutdown are
    recorded instead (the README's batch example runs them for real)."""
    pytest.importorskip("ray.data", reason="Ray Data is not installed (pip install 'gesturecast[scale]')")
    started, stopped = [], []
    monkeypatch.setattr(ray_cluster, "init", lambda **options: started.append(options))
    monkeypatch.setattr(ray_cluster, "shutdown", lambda: stopped.append(True))
    model = ["--model", str(tiny_model[1])]
    by_processes, by_ray = tmp_path / "processes", tmp_path / "ray"
    run_cli("generate", "--batch", str(clips), "-o", str(by_processes), "--workers", "1", *model)
    result = cli_here("generate", "--batch", str(clips), "-o", str(by_ray), "--workers", "2", "--ray", *model)
    assert result.returncode == BATCH_FAILED_EXIT, result.stderr[-3000:]
    assert [options["num_cpus"] for options in started] == [2] and stopped == [True]
    summary = read_summary(by_ray)
    assert (summary["runner"], summary["generated"], summary["failed"]) == ("ray", 2, 2)
    assert sorted(Path(f["path"]).name for f in summary["failures"]) == ["corrupt.wav", "empty.wav"]
    for name in ("a.bvh", "sub/b.bvh"):
        assert (by_ray / name).read_bytes() == (by_processes / name).read_bytes()


def test_ray_without_the_extra_names_the_install_command(tiny_model, clips, tmp_path):
    result = run_cli("generate", "--batch", str(clips), "-o", str(tmp_path / "out"), "--ray",
                     "--model", str(tiny_model[1]), prelude="import sys; sys.modules['ray'] = None; ")
    assert result.returncode == 2, result.stderr[-2000:]
    assert "pip install 'gesturecast[scale]'" in result.stderr.splitlines()[-1]


INTERRUPT_FILES = 24
INTERRUPT_CLIP_S = 2.0
INTERRUPT_BOUND_S = 60.0  # the files already running finish first; generous for shared cores
POLL_S = 0.05


def test_ctrl_c_stops_after_the_running_file_and_the_next_run_resumes(tiny_model, shared_data, cli_process,
                                                                       tmp_path):
    speech = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")  # (n,)
    n = int(INTERRUPT_CLIP_S * SAMPLE_RATE)
    (tmp_path / "in").mkdir()
    for i in range(INTERRUPT_FILES):
        soundfile.write(tmp_path / "in" / f"line_{i:02d}.wav", speech[i * n : (i + 1) * n], SAMPLE_RATE)
    out = tmp_path / "out"
    argv = ["generate", "--batch", str(tmp_path / "in"), "-o", str(out), "--workers", "1",
            "--model", str(tiny_model[1])]
    batch = cli_process(argv)
    deadline = time.monotonic() + INTERRUPT_BOUND_S
    while not list(out.glob("*.bvh")) and time.monotonic() < deadline:
        time.sleep(POLL_S)
    status, _, stdout = batch.interrupt(INTERRUPT_BOUND_S)
    summary = read_summary(out)
    assert status == 130 and summary["interrupted"] and stdout.startswith("stopped by Ctrl-C: ")
    written = sorted(out.glob("*.bvh"))
    assert 1 <= summary["generated"] == len(written) < INTERRUPT_FILES
    assert all(read_bvh(path).motion.shape[0] == INTERRUPT_CLIP_S * 30 for path in written)  # complete files
    assert not list(out.glob(".*.tmp"))  # nothing half-written left behind

    again = run_cli(*argv)
    assert again.returncode == 0, again.stderr[-2000:]
    assert (read_summary(out)["skipped"], read_summary(out)["generated"]) == (
        len(written), INTERRUPT_FILES - len(written))
