"""The generation and output flags shared by ``live``, ``generate``, ``demo``, ``serve`` and the benchmarks (and
``generate --batch``'s), and their translation into :class:`Settings` and :class:`Outputs` (the only place flags
become settings). Nothing here loads the engine: a command's ``--help`` needs only these.

Each numeric flag takes its range from :data:`gesturecast.settings.NUMBER_LIMITS`, so ``--steps 0`` and
``Settings(steps=0)`` are refused in the same words.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
from pathlib import Path

from gesturecast.arguments import int_at_least, port_number
from gesturecast.bridges.avatar_file import AVATAR_ENV_VAR
from gesturecast.bridges.coords import FRAMES
from gesturecast.bridges.output_settings import VMC_ROLES, Outputs
from gesturecast.bridges.vmc_roles import MARIONETTE
from gesturecast.bridges.ws_access import MIN_TOKEN_CHARS, TOKEN_ENV_VAR, token_from_sources
from gesturecast.controls import ROOT_MODES
from gesturecast.frames import VISEME_NAMES
from gesturecast.settings import (
    DEFAULT_MODEL_DIR,
    FACE_MODES,
    LATENCY_SETTINGS,
    LIPSYNC_OFF,
    NUMBER_LIMITS,
    OUTPUT_RATES,
    SAMPLERS,
    Settings,
)

GESTURES_OFF = "off"
SETTING_NAMES = tuple(field.name for field in dataclasses.fields(Settings))
FLAG_ALIASES = {"part_style": "part_styles"}  # flag destination -> Settings field


def _limited(name: str) -> dict:
    """The ``type`` keyword of a numeric flag: the range of the setting ``name``."""
    return {"type": NUMBER_LIMITS[name].flag_type()}


def add_generation_arguments(parser: argparse.ArgumentParser) -> None:
    defaults = Settings()
    group = parser.add_argument_group("generation")
    group.add_argument("--model", type=Path, default=DEFAULT_MODEL_DIR, help="model bundle directory")
    group.add_argument("--style", default=defaults.style, help="style label (e.g. happy, old), text:FREE TEXT, "
                       "or motion:CLIP.bvh")
    group.add_argument("--prompt", help="free-text style prompt (same as --style text:...)")
    group.add_argument("--motion-prompt", type=Path, help="a BVH/NPZ clip whose style to imitate")
    group.add_argument("--part-style", nargs="+", default=[], metavar="PART=STYLE",
                       help="a style per body part (arms, torso, legs), e.g. arms=happy \"legs=text:tired\"; "
                            "parts not named follow --style (docs/part-styles.md)")
    group.add_argument("--style2", help="a second style to mix with --style (the mix is set by --gamma)")
    group.add_argument("--gamma", default=defaults.gamma, **_limited("gamma"),
                       help="how much of --style against --style2: 1 only --style, 0.5 half each, 0 only --style2, "
                            "above 1 exaggerates --style away from --style2 (default %(default)s)")
    group.add_argument("--style-strength", default=defaults.style_strength, **_limited("style_strength"),
                       help="how strongly the style shows: 0 neutral, 1 the model's default, up to 2")
    group.add_argument("--generator-style", default=defaults.generator_style, metavar="LABEL",
                       help="the label the generator hears under the stylizer's styles: speech (the default) "
                            "follows the voice; neutral is the generator's own neutral, learned from motion without "
                            "speech (docs/voices.md)")
    group.add_argument("--intensity", default=defaults.intensity, **_limited("intensity"),
                       help="gesture size: 0 stands, breathes and blinks, 1 the gestures as generated (default), "
                            "up to 2 twice as big; changes live with an intensity control")
    group.add_argument("--guidance", **_limited("guidance"),
                       help="how closely the motion follows the style and speech prompts; higher shows styles "
                            "more (4 is clear) but follows the speech less (default: the model's)")
    group.add_argument("--audio-guidance", default=defaults.audio_guidance, **_limited("audio_guidance"),
                       help="how strongly the motion follows the speech: above 1 more, 1 no extra pull (and a "
                            "little less computing); default %(default)s")
    group.add_argument("--sampler", choices=SAMPLERS, default=defaults.sampler,
                       help="ddim: a few steps, fast enough for live use (default); ddpm: the full 1000 steps, "
                            "offline quality, 250 times the work")
    group.add_argument("--steps", default=defaults.steps, **_limited("steps"),
                       help="denoising steps per 4 frames with ddim: more is smoother and slower "
                            "(default: the model's, 2 for the bundled one)")
    group.add_argument("--seed", default=defaults.seed, **_limited("seed"),
                       help="random seed: the same speech and seed give the same motion, another seed other "
                            "gestures (default %(default)s)")
    group.add_argument("--latency", choices=tuple(LATENCY_SETTINGS), default=defaults.latency,
                       help="how far behind the voice the poses come: quality 533 ms (hears 8 frames ahead, the "
                            "default), balanced 380 ms, low 247 ms (hears no audio ahead); docs/latency.md")
    group.add_argument("--lookahead", **_limited("lookahead"),
                       help="frames of audio the model hears ahead of each pose (default: the --latency "
                            "setting's)")
    group.add_argument("--smoothing", default=defaults.smoothing, **_limited("smoothing"),
                       help="frames averaged on each side of a pose to smooth the motion; each adds a frame "
                            "(33 ms) of delay; 0 turns smoothing off (default %(default)s)")
    group.add_argument("--margin-ms", **_limited("margin_ms"),
                       help="milliseconds of delay kept for computing each pose (default: the --latency "
                            "setting's)")
    group.add_argument("--threads", default=defaults.threads, **_limited("threads"),
                       help="onnxruntime intra-op threads")
    group.add_argument("--seed-motion", type=Path, metavar="FILE",
                       help="start from this motion's last pose instead of the idle pose (BVH of any supported "
                            "skeleton, or SMPL-X .npz; its last frames seed the generator)")
    group.add_argument("--lipsync", choices=(*VISEME_NAMES, LIPSYNC_OFF), default=defaults.lipsync,
                       help="viseme blend shapes from the audio (docs/lipsync.md): vrm0 = A I U E O (VRM 0.x), "
                            "vrm1 = aa ih ou ee oh (VRM 1.0), off")
    group.add_argument("--face", choices=FACE_MODES, default=defaults.face,
                       help="the face besides the mouth: full = blinks and the style's expression (default), blink, "
                            "off; blend shapes named like --lipsync (docs/face.md)")
    group.add_argument("--gestures", type=gestures_folder, default=defaults.gestures, metavar="DIR|off",
                       help="gesture lexicon that trigger words and gesture controls draw on: the bundled one "
                            "(default), a folder of your own clips with gestures.json (docs/gestures.md), or off")
    group.add_argument("--root", choices=ROOT_MODES, default=defaults.root,
                       help="bounded: stays within 0.15 m / 30° of where it started (default); "
                            "free: the generated root motion; locked: pinned in place")


def gestures_folder(text: str) -> Path | None:
    """``--gestures``: a folder, or ``off`` (None: no lexicon)."""
    return None if text == GESTURES_OFF else Path(text)


def add_batch_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("batch (many files)")
    group.add_argument("--batch", type=Path, metavar="DIR_OR_CSV",
                       help="every audio file under a folder, or the rows of a CSV (columns: path, style, prompt, "
                            "style2, part_style, gamma, style_strength, guidance, audio_guidance, seed, "
                            "transcript); -o is then the output folder")
    group.add_argument("--workers", type=int_at_least(1), default=os.cpu_count() or 1,
                       help="worker processes (or Ray actors) for --batch (default: every core)")
    group.add_argument("--with-json", action="store_true", help="with --batch: also write NAME.json beside NAME.bvh")
    group.add_argument("--with-vrma", action="store_true",
                       help="with --batch: also write NAME.vrma (VRM Animation) beside NAME.bvh")
    group.add_argument("--ray", action="store_true",
                       help="with --batch: run on Ray Data (pip install 'gesturecast[scale]') instead of processes")


def add_transcript_argument(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--transcript", type=Path, metavar="FILE",
                        help="the words of the audio: with times (JSON [{word, start, end}], .srt, .vtt) or a "
                             "plain-text script (.txt, placed on the audio; a NAME.txt beside the audio is read "
                             "without this flag): speech acts cue gestures on their words (docs/gestures.md)")


def add_output_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("outputs")
    group.add_argument("--vmc", metavar="HOST[:PORT]", help="VMC over OSC/UDP (VSeeFace, Warudo, EVMC4U, VMC4UE, "
                       "VirtualMotionCapture); default port 39539, or 39540 with --vmc-role assistant")
    group.add_argument("--vmc-role", choices=VMC_ROLES, default=MARIONETTE,
                       help="marionette: the receiver shows our whole avatar (root + all bones); assistant: a "
                            "Performer mixes our bones/visemes with its own tracking (no root; docs/bridges.md)")
    group.add_argument("--vmc-bones", metavar="BONES",
                       help="bones sent over VMC: all, upper (no hips, legs, neck, head), arms, none (visemes "
                            "only) or a comma list of HumanBodyBones names; default all (assistant: upper)")
    group.add_argument("--osc", metavar="HOST:PORT", help="plain OSC (Unreal OSC plugin, TouchDesigner)")
    group.add_argument("--osc-frame", choices=tuple(FRAMES), default="unity",
                       help="coordinates of the --osc quaternions: unity (left-handed, default), unreal, or "
                            "internal (right-handed, Y up, facing +Z)")
    group.add_argument("--ws", metavar="PORT", type=port_number(allow_any=True),
                       help="WebSocket stream + browser viewer on this port")
    group.add_argument("--avatar", type=Path, metavar="FILE.vrm",
                       help=f"VRM avatar the viewer shows (default: ${AVATAR_ENV_VAR}, else the packaged "
                       "cryptovoxels.vrm by jin; a .vrm dropped on the page replaces it)")
    group.add_argument("--host", default="127.0.0.1", help="listen address of the WebSocket server")
    add_access_arguments(group)
    group.add_argument("--bvh", type=Path, metavar="FILE", help="record the stream as BVH")
    group.add_argument("--fps", type=int, choices=OUTPUT_RATES, default=30, help="output rate (60 = slerp upsampling)")


def add_access_arguments(group: argparse._ArgumentGroup) -> None:
    """--token / --token-file / --allow-origin of a WebSocket server (live --ws, serve); docs/bridges.md."""
    group.add_argument("--token", help=f"shared secret clients must send (>= {MIN_TOKEN_CHARS} characters; needed "
                       f"beyond loopback). `ps` shows it: prefer --token-file or ${TOKEN_ENV_VAR}")
    group.add_argument("--token-file", type=Path, metavar="FILE", help="read the token from this file")
    group.add_argument("--allow-origin", action="append", default=[], metavar="ORIGIN",
                       help="also accept browser pages from this origin (e.g. http://localhost:3000); repeatable")


def settings_from_args(args: argparse.Namespace, **changes) -> Settings:
    """The :class:`Settings` of the generation flags (flags a command lacks keep their defaults), with ``changes``."""
    values = {FLAG_ALIASES.get(name, name): value for name, value in vars(args).items()
              if FLAG_ALIASES.get(name, name) in SETTING_NAMES}
    return Settings(**{**values, **changes})


def outputs_from_args(args: argparse.Namespace, **changes) -> Outputs:
    """The :class:`Outputs` of the output flags, with ``changes``."""
    values = dict(vmc=args.vmc, vmc_role=args.vmc_role, vmc_bones=args.vmc_bones, osc=args.osc,
                  osc_frame=args.osc_frame, ws=args.ws, host=args.host, token=args.token, token_file=args.token_file,
                  allow_origins=tuple(args.allow_origin), avatar=args.avatar, bvh=args.bvh)
    return Outputs(**{**values, **changes})


def server_token(args: argparse.Namespace) -> str | None:
    """The token from --token, --token-file or the environment (ws_access.token_from_sources)."""
    return token_from_sources(args.token, args.token_file)
