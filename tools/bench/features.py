"""``gesturecast bench features FILE``: cost of the streaming speech features on this machine.

The file is streamed in bounded blocks (:class:`FastFileSource`) and pushed chunk by chunk
through one :class:`StreamingFeatureExtractor`, as live audio would be. Reported:
- ``rtf``: compute seconds per second of audio (time spent inside ``push`` only, decoding
  excluded), median over ``--repeats`` runs;
- ``chunk_ms``: p50/p95/p99/max of the per-push time over all runs;
- ``peak_rss_mb`` (``ru_maxrss``) next to the RSS before the first run: memory stays bounded
  because neither the file nor the features are ever held whole.
``--tile-minutes M`` first writes FILE repeated to M minutes into ``.cache/bench/`` (in blocks).
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import soundfile

from gesturecast.models.audio.streaming import FeatureConfig, StreamingFeatureExtractor
from gesturecast.models.audio.vad import VadConfig
from gesturecast.realtime.audio.sources import DEFAULT_CHUNK, FastFileSource

TILE_DIR = Path(".cache/bench")
TILE_BLOCK = 1 << 16  # frames copied per write when tiling
PERCENTILES = (50, 95, 99)
KIB_PER_MIB = 1024.0
MS_PER_S = 1000.0
WARMUP_SAMPLES = 16000


def register_bench(bench_subparsers: argparse._SubParsersAction) -> None:
    parser = bench_subparsers.add_parser("features", help="streaming speech-feature cost (rtf, per-chunk ms, memory)")
    parser.add_argument("file", type=Path, help="speech audio file (any rate/channels soundfile reads)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--repeats", type=int, default=3, help="runs; rtf is their median")
    parser.add_argument("--chunk", type=int, default=DEFAULT_CHUNK, help="samples per push (16 kHz)")
    parser.add_argument("--vad", choices=("energy", "silero"), default=VadConfig().method)
    parser.add_argument("--speech-embedding", action="store_true", help="include the 96-d embedding channel")
    parser.add_argument("--tile-minutes", type=float, help="benchmark FILE tiled to this many minutes")
    parser.set_defaults(func=run)


def tile_file(source: Path, minutes: float, out_dir: Path = TILE_DIR) -> Path:
    """Write ``source`` repeated to ``minutes`` long (same rate/channels), block by block."""
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / f"{source.stem}_{minutes:g}min.wav"
    info = soundfile.info(str(source))
    remaining = int(minutes * 60 * info.samplerate)
    if target.exists() and soundfile.info(str(target)).frames == remaining:
        return target
    with soundfile.SoundFile(str(target), "w", info.samplerate, info.channels, subtype=info.subtype) as out:
        while remaining > 0:
            for block in soundfile.blocks(str(source), blocksize=TILE_BLOCK, always_2d=True, dtype="float32"):
                piece = block[:remaining]
                out.write(piece)
                remaining -= piece.shape[0]
                if remaining <= 0:
                    break
    return target


def time_one_run(path: Path, config: FeatureConfig, chunk: int) -> tuple[float, list[float], float, int]:
    """→ (compute seconds, per-push seconds, audio seconds, frames)."""
    extractor = StreamingFeatureExtractor(config)
    extractor.push(np.zeros(WARMUP_SAMPLES, np.float32))
    extractor.reset()
    push_times: list[float] = []
    samples = 0
    for audio_chunk in FastFileSource(path, chunk_samples=chunk):
        started = time.perf_counter()
        extractor.push(audio_chunk.samples)
        push_times.append(time.perf_counter() - started)
        samples += audio_chunk.samples.shape[0]
    return sum(push_times), push_times, samples / config.sample_rate, extractor.frames_emitted


def peak_rss_mb() -> float | None:
    """The process's peak resident set size so far (MiB), or None where there is no ``resource`` (Windows)."""
    try:
        import resource
    except ImportError:
        return None
    return round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / KIB_PER_MIB, 1)


def benchmark(path: Path, config: FeatureConfig, chunk: int, repeats: int) -> dict:
    baseline_mb = peak_rss_mb()
    runs = [time_one_run(path, config, chunk) for _ in range(repeats)]
    audio_s = runs[0][2]
    all_pushes = np.array([t for run in runs for t in run[1]]) * MS_PER_S
    rtfs = [run[0] / audio_s for run in runs]
    return {
        "file": str(path),
        "audio_s": round(audio_s, 3),
        "frames": runs[0][3],
        "chunk_samples": chunk,
        "repeats": repeats,
        "vad": config.vad.method,
        "speech_embedding": config.speech_embedding,
        "rtf": statistics.median(rtfs),
        "rtf_runs": rtfs,
        "chunk_ms": {f"p{p}": float(np.percentile(all_pushes, p)) for p in PERCENTILES}
        | {"max": float(all_pushes.max())},
        "baseline_rss_mb": baseline_mb,
        "peak_rss_mb": peak_rss_mb(),
    }


def run(args: argparse.Namespace) -> int:
    from gesturecast.models.audio.files import AudioFileReader

    AudioFileReader(args.file)  # validates the file (one-line errors) before any tiling
    path = tile_file(args.file, args.tile_minutes) if args.tile_minutes else args.file
    config = FeatureConfig(vad=VadConfig(method=args.vad), speech_embedding=args.speech_embedding)
    result = benchmark(path, config, args.chunk, args.repeats)
    if args.json:
        sys.stdout.write(json.dumps(result) + "\n")
    else:
        ms = result["chunk_ms"]
        sys.stdout.write(
            f"{result['audio_s']:.1f} s of audio, chunk {args.chunk}: rtf {result['rtf']:.4f}, "
            f"chunk ms p50 {ms['p50']:.3f} p95 {ms['p95']:.3f} p99 {ms['p99']:.3f}, "
            f"peak RSS {result['peak_rss_mb']} MB (baseline {result['baseline_rss_mb']} MB)\n"
        )
    return 0
