"""bench features / bench vad produce their JSON fields (values are measurements, not asserted)."""

import argparse
import json

import numpy as np
import soundfile

from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.tools.bench import bench_command as bench_cli
from gesturecast.tools.bench.features import tile_file


def parse(argv):
    parser = argparse.ArgumentParser()
    bench_cli.register(parser.add_subparsers(dest="command"))
    return parser.parse_args(argv)


def test_bench_features_json(shared_data, tmp_path, capsys):
    path = tmp_path / "short.wav"
    speech = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")[5 * SAMPLE_RATE : 8 * SAMPLE_RATE]
    soundfile.write(path, speech, SAMPLE_RATE)
    args = parse(["bench", "features", str(path), "--json", "--repeats", "2", "--vad", "energy"])
    assert args.func(args) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["frames"] == 90 and len(result["rtf_runs"]) == 2
    assert result["rtf"] > 0 and set(result["chunk_ms"]) == {"p50", "p95", "p99", "max"}
    assert result["peak_rss_mb"] >= result["baseline_rss_mb"] > 0


def test_tile_file_repeats_the_source(tmp_path):
    source = tmp_path / "one.wav"
    soundfile.write(source, np.arange(1000, dtype=np.int16), SAMPLE_RATE, subtype="PCM_16")
    tiled = tile_file(source, 2500 / SAMPLE_RATE / 60, tmp_path / "out")
    data, _ = soundfile.read(tiled, dtype="int16")
    np.testing.assert_array_equal(data, np.concatenate([np.arange(1000)] * 3)[:2500])
