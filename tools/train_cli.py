"""`gesturecast train`: train the generator (VQ-VAE, denoiser, motion prompt) from the dataset cache.

Checkpoints go to ``--work-dir`` (default ``.cache/train/<preset>``, never committed); with
``--out`` the finished model is also exported as a bundle (``gesturecast export`` does it later).
"""

from __future__ import annotations

import argparse
import json
import logging
import time
from pathlib import Path

from gesturecast.models.audio.speaker_norm import SpeakerNormConfig
from gesturecast.models.audio.streaming import FeatureConfig
from gesturecast.models.training.presets import PRESETS, get_preset

LOGGER = logging.getLogger(__name__)
DEFAULT_DATA = Path(".cache/dataset")
DEFAULT_WORK_ROOT = Path(".cache/train")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("train", help="train the gesture generator from the dataset cache")
    parser.add_argument("--preset", choices=sorted(PRESETS), default="default", help="sizes and steps")
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA, help="dataset cache (default %(default)s)")
    parser.add_argument("--work-dir", type=Path, default=None, help="checkpoint folder (default .cache/train/PRESET)")
    parser.add_argument("--out", type=Path, default=None, help="also export the bundle to this folder")
    parser.add_argument("--resume", action="store_true", help="continue from the checkpoint's finished stages")
    parser.add_argument("--seed", type=int, default=None, help="random seed (default: the preset's)")
    parser.add_argument("--lookahead", type=int, default=None,
                        help="frames of audio the model hears ahead of each pose (default 8)")
    parser.add_argument("--threads", type=int, default=None, help="torch CPU threads (default: the preset's)")
    parser.add_argument("--audio-augmentation", action=argparse.BooleanOptionalAction, default=None,
                        help="voice / channel augmentation of the paired audio (default: the preset's)")
    parser.add_argument("--lookahead-truncation", action=argparse.BooleanOptionalAction, default=None,
                        help="train with a random look-ahead from 0 to --lookahead, so one model serves every "
                             "--latency setting (default: the preset's)")
    parser.add_argument("--speaker-norm", action=argparse.BooleanOptionalAction, default=None,
                        help="listen to speaker-normalised log-mel / energy (docs/voices.md; default: the preset's)")
    parser.add_argument("--warm-start", action=argparse.BooleanOptionalAction, default=None,
                        help="with --speaker-norm: the voice's mean starts from the speech heard so far, not a fixed "
                             "prior (docs/unseen-voices-study.md; default: the preset's)")
    parser.add_argument("--front-end", choices=("mel", "prosody"), default=None,
                        help="speech features: log-mel or prosody (default: the preset's; docs/voices.md)")
    parser.add_argument("--speech-embedding", action=argparse.BooleanOptionalAction, default=None,
                        help="add the packaged 96-d speech embedding to the features (default: the preset's)")
    parser.add_argument("--speech-embedding-every", type=int, default=None, metavar="N",
                        help="with --speech-embedding: one embedding every N × 80 ms, held between (default: the "
                             "preset's, 1)")
    parser.add_argument("--voice-copies", type=int, default=None,
                        help="waveform-augmented voice copies per paired train clip (default: the preset's)")
    parser.add_argument("--respoken-copies", type=int, default=None, metavar="N",
                        help="TTS voices (espeak-ng) re-speaking each paired take's words in time with its motion, "
                             "0-8 (needs pocketsphinx; docs/unseen-voices-study.md; default: the preset's)")
    parser.add_argument("--partial-takes", action=argparse.BooleanOptionalAction, default=None,
                        help="also train on takes that hold only some body parts (SHOW: arms), the others masked "
                             "(default: the preset's; docs/dataset.md)")
    parser.add_argument("--style-loss-weight", type=float, default=None, metavar="W",
                        help="GestureDiffuCLIP's style loss on the denoiser (Eq. 16; the paper uses 0.07; default: "
                             "the preset's, off)")
    parser.add_argument("--style-swap", type=float, default=None, metavar="P",
                        help="share of speech sequences trained with a drawn style and the style loss, so styles "
                             "hold while speech is heard (docs/style-study.md; default: the preset's, off)")
    parser.add_argument("--style-swap-weight", type=float, default=None, metavar="W",
                        help="the style loss's weight on those sequences (default: the preset's, 0.3)")
    parser.add_argument("--style-swap-parts", nargs="+", default=None, metavar="PART",
                        help="the body parts a swap restyles, e.g. torso legs: the others keep the take's motion "
                             "and follow the speech (default: the preset's, all)")
    parser.add_argument("--paired-style", default=None, metavar="LABEL",
                        help="train every take with speech under this style label, e.g. speech (default: the "
                             "preset's, each take's own)")
    parser.add_argument("--denoiser-layers", type=int, default=None, metavar="N",
                        help="transformer layers of the denoiser (default: the preset's; fewer run cheaper)")
    parser.add_argument("--vq-from", type=Path, default=None,
                        help="reuse the VQ-VAE of this finished work folder instead of training one")
    parser.add_argument("--vq-steps", type=int, default=None,
                        help="training steps of the motion VQ-VAE (default: the preset's)")
    parser.add_argument("--denoiser-steps", type=int, default=None,
                        help="training steps of the denoiser (default: the preset's)")
    parser.add_argument("--prompt-steps", type=int, default=None,
                        help="training steps of the motion-prompt encoder (default: the preset's)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    parser.set_defaults(func=run_train)


def run_train(args: argparse.Namespace) -> int:
    from gesturecast.models.export.bundle import export_bundle, training_summary
    from gesturecast.models.training.pipeline import run_training

    preset = get_preset(args.preset, seed=args.seed, audio_lookahead=args.lookahead, threads=args.threads,
                        audio_augmentation=args.audio_augmentation, voice_copies=args.voice_copies,
                        respoken_copies=args.respoken_copies,
                        front_end=args.front_end, speaker_norm=args.speaker_norm, warm_start=args.warm_start,
                        speech_embedding=args.speech_embedding, speech_embedding_every=args.speech_embedding_every,
                        lookahead_truncation=args.lookahead_truncation, partial_takes=args.partial_takes,
                        style_loss_weight=args.style_loss_weight, style_swap_prob=args.style_swap,
                        style_swap_weight=args.style_swap_weight,
                        style_swap_parts=None if args.style_swap_parts is None else tuple(args.style_swap_parts),
                        paired_style=args.paired_style, denoiser_layers=args.denoiser_layers, vq_steps=args.vq_steps,
                        denoiser_steps=args.denoiser_steps, prompt_steps=args.prompt_steps)
    work_dir = args.work_dir or DEFAULT_WORK_ROOT / preset.name
    started = time.perf_counter()
    features = FeatureConfig(speaker_norm=SpeakerNormConfig(enabled=preset.speaker_norm, warm_start=preset.warm_start),
                             kind=preset.front_end,
                             speech_embedding=preset.speech_embedding,
                             speech_embedding_every=preset.speech_embedding_every)
    checkpoint = run_training(preset, args.data, work_dir, resume=args.resume, progress=not args.no_progress,
                              feature_config=features, vq_from=args.vq_from)
    if args.out is not None:
        export_bundle(checkpoint, args.out)
        LOGGER.info("bundle written to %s", args.out)
    summary = {"checkpoint": str(work_dir), "bundle": None if args.out is None else str(args.out),
               "wall_seconds": round(time.perf_counter() - started, 1), **training_summary(checkpoint)}
    print(json.dumps(summary, indent=1))
    return 0
