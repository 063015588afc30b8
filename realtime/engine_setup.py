"""Building a session and its outputs from command-line flags (shared by live, demo, generate, bench)."""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

from gesturecast.arguments import finite_float, int_at_least, port_number
from gesturecast.bridges.avatar_file import AVATAR_ENV_VAR, resolve_avatar
from gesturecast.bridges.bvh_recorder import BvhRecorder
from gesturecast.bridges.fanout import BridgeFanout
from gesturecast.bridges.osc import OscBridge, OscConfig
from gesturecast.bridges.vmc import VmcBridge, VmcConfig
from gesturecast.bridges.vmc_roles import ASSISTANT, DEFAULT_PORTS, MARIONETTE, BoneSelection
from gesturecast.bridges.websocket_server import WebSocketBridge, WebSocketConfig
from gesturecast.bridges.ws_access import MIN_TOKEN_CHARS, TOKEN_ENV_VAR, token_from_sources
from gesturecast.errors import UserError
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.motion.root_anchor import ROOT_MODES, RootMode
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.generator import SINGLE_STYLE, Generator, GeneratorSettings
from gesturecast.realtime.seed_motion import load_seed_motion
from gesturecast.realtime.session import GestureSession, SessionConfig
from gesturecast.realtime.style_prompts import StylePrompt, parse_part_styles
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.frames import VISEME_NAMES
from gesturecast.realtime.timing.latency import LATENCY_SETTINGS, QUALITY, LatencyBudget, LatencySetting

DEFAULT_MODEL_DIR = Path(str(resources.files("gesturecast.models"))) / "weights" / "default"
DEFAULT_MARGIN_MS = QUALITY.compute_margin_ms
DEFAULT_SMOOTHING_FRAMES = 1  # centred 3-frame window: jerk ≈ real motion's (docs/generator.md "Smoothing")
DEFAULT_STEPS = 4
LIPSYNC_OFF = "off"
DEFAULT_AUDIO_GUIDANCE = 1.5  # docs/generator.md "Audio guidance": rests in pauses, follows the speech more


def add_generation_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("generation")
    group.add_argument("--model", type=Path, default=DEFAULT_MODEL_DIR, help="model bundle directory")
    group.add_argument("--style", default="neutral", help="style label (e.g. happy, old), text:FREE TEXT, "
                       "or motion:CLIP.bvh")
    group.add_argument("--prompt", help="free-text style prompt (same as --style text:...)")
    group.add_argument("--motion-prompt", type=Path, help="a BVH/NPZ clip whose style to imitate")
    group.add_argument("--part-style", nargs="+", default=[], metavar="PART=STYLE",
                       help="a style per body part (arms, torso, legs), e.g. arms=happy \"legs=text:tired\"; "
                            "parts not named follow --style (docs/part-styles.md)")
    group.add_argument("--style2", help="second style for γ interpolation/extrapolation")
    group.add_argument("--gamma", type=finite_float(), default=SINGLE_STYLE,
                       help="x̂0 = γ·D(style) + (1 − γ)·D(style2)")
    group.add_argument("--guidance", type=finite_float(),
                       help="classifier-free guidance scale s (default: the model's)")
    group.add_argument("--audio-guidance", type=finite_float(), default=DEFAULT_AUDIO_GUIDANCE,
                       help="audio guidance s_a: > 1 makes the motion follow the speech more, 1 turns it off "
                            "(one batch row less)")
    group.add_argument("--sampler", choices=("ddim", "ddpm"), default="ddim")
    group.add_argument("--steps", type=int_at_least(1), default=DEFAULT_STEPS, help="DDIM steps K per latent frame")
    group.add_argument("--seed", type=int_at_least(0), default=0)
    group.add_argument("--latency", choices=tuple(LATENCY_SETTINGS), default=QUALITY.name,
                       help="latency dial: quality = the model's look-ahead δa (L 533 ms), balanced = δ 4, "
                            "low = δ 0 (L 247 ms); below δa needs a model trained with look-ahead truncation "
                            "(docs/latency.md)")
    group.add_argument("--lookahead", type=int_at_least(0),
                       help="audio look-ahead δ in frames (default: the --latency setting's)")
    group.add_argument("--smoothing", type=int_at_least(0), default=DEFAULT_SMOOTHING_FRAMES,
                       help="half-width k of the centred motion smoothing window in frames (adds k frames to L; "
                            "0: off)")
    group.add_argument("--margin-ms", type=finite_float(minimum=0.0),
                       help="compute margin in the latency L (default: the --latency setting's)")
    group.add_argument("--threads", type=int_at_least(1), default=1, help="onnxruntime intra-op threads")
    group.add_argument("--seed-motion", type=Path, metavar="FILE",
                       help="start from this motion's last pose instead of the idle pose (BVH of any supported "
                            "skeleton, or SMPL-X .npz; its last frames seed the generator)")
    group.add_argument("--lipsync", choices=(*VISEME_NAMES, LIPSYNC_OFF), default="vrm0",
                       help="viseme blend shapes from the audio (docs/lipsync.md): vrm0 = A I U E O (VRM 0.x), "
                            "vrm1 = aa ih ou ee oh (VRM 1.0), off")
    group.add_argument("--root", choices=ROOT_MODES, default=RootMode.BOUNDED.value,
                       help="bounded: stays within 0.15 m / 30° of where it started (default); "
                            "free: the generated root motion; locked: pinned in place")


def load_bundle(path: Path) -> ModelBundle:
    if not (path / "model.json").is_file():
        raise UserError(f"no model bundle at {path} (expected model.json); train one with `gesturecast train`")
    return ModelBundle.load(path)


def style_prompt(args: argparse.Namespace) -> StylePrompt:
    if args.motion_prompt is not None:
        return StylePrompt("motion", str(args.motion_prompt))
    if args.prompt:
        return StylePrompt("text", args.prompt)
    return StylePrompt.parse(args.style)


def latency_choice(args: argparse.Namespace, bundle: ModelBundle) -> tuple[int, float]:
    """(look-ahead δ, compute margin ms) of --latency, with --lookahead / --margin-ms overriding it."""
    setting: LatencySetting = LATENCY_SETTINGS[args.latency]
    lookahead = setting.lookahead_for(bundle.audio_lookahead) if args.lookahead is None else args.lookahead
    margin = setting.compute_margin_ms if args.margin_ms is None else args.margin_ms
    return lookahead, margin


def generator_settings(args: argparse.Namespace, bundle: ModelBundle) -> GeneratorSettings:
    """DDIM with K steps, or DDPM over all T steps of the model's schedule (the offline-quality path)."""
    steps = args.steps if args.sampler == "ddim" else bundle.denoiser_config.num_timesteps
    sampler = SamplerConfig(args.sampler, steps)
    lookahead, _ = latency_choice(args, bundle)
    return GeneratorSettings(
        sampler=sampler,
        guidance=args.guidance,
        style=style_prompt(args),
        second_style=StylePrompt.parse(args.style2) if args.style2 else None,
        gamma=args.gamma,
        seed=args.seed,
        threads=args.threads,
        audio_guidance=args.audio_guidance,
        lookahead=lookahead,
        part_styles=parse_part_styles(args.part_style),
    )


def build_session(args: argparse.Namespace, clock: Clock, bundle: ModelBundle | None = None) -> GestureSession:
    """A session with the flags' settings, on ``bundle`` (loaded once by batch workers) or on ``--model``."""
    bundle = load_bundle(args.model) if bundle is None else bundle
    generator = Generator(bundle, generator_settings(args, bundle))
    _, margin = latency_choice(args, bundle)
    budget = LatencyBudget(bundle.frames_per_latent, generator.lookahead, margin, smoothing_frames=args.smoothing)
    seed = None if args.seed_motion is None else load_seed_motion(args.seed_motion, bundle)
    config = SessionConfig(root_mode=RootMode(args.root), seed_motion=seed, lipsync=args.lipsync)
    return GestureSession(bundle, generator, budget, clock, config)


def viseme_names(args: argparse.Namespace) -> tuple[str, ...]:
    """The blend-shape names of ``--lipsync`` (VRM 0.x or 1.0), () when off."""
    return VISEME_NAMES.get(args.lipsync, ())


def add_output_arguments(parser: argparse.ArgumentParser) -> None:
    group = parser.add_argument_group("outputs")
    group.add_argument("--vmc", metavar="HOST[:PORT]", help="VMC over OSC/UDP (VSeeFace, Warudo, EVMC4U, VMC4UE, "
                       "VirtualMotionCapture); default port 39539, or 39540 with --vmc-role assistant")
    group.add_argument("--vmc-role", choices=(MARIONETTE, ASSISTANT), default=MARIONETTE,
                       help="marionette: the receiver shows our whole avatar (root + all bones); assistant: a "
                            "Performer mixes our bones/visemes with its own tracking (no root; docs/bridges.md)")
    group.add_argument("--vmc-bones", metavar="BONES",
                       help="bones sent over VMC: all, upper (no hips, legs, neck, head), arms, none (visemes "
                            "only) or a comma list of HumanBodyBones names; default all (assistant: upper)")
    group.add_argument("--osc", metavar="HOST:PORT", help="plain OSC (Unreal OSC plugin, TouchDesigner)")
    group.add_argument("--osc-frame", choices=("unity", "unreal", "internal"), default="unity")
    group.add_argument("--ws", metavar="PORT", type=port_number(allow_any=True),
                       help="WebSocket stream + browser viewer on this port")
    group.add_argument("--avatar", type=Path, metavar="FILE.vrm",
                       help=f"VRM avatar the viewer shows (default: ${AVATAR_ENV_VAR}, else "
                       "../shared/assets/cryptovoxels.vrm next to the checkout, else the stick figure)")
    group.add_argument("--host", default="127.0.0.1", help="listen address of the WebSocket server")
    add_access_arguments(group)
    group.add_argument("--bvh", type=Path, metavar="FILE", help="record the stream as BVH")
    group.add_argument("--fps", type=int, choices=(30, 60), default=30, help="output rate (60 = slerp upsampling)")


def add_access_arguments(group: argparse._ArgumentGroup) -> None:
    """--token / --token-file / --allow-origin of a WebSocket server (live --ws, serve); docs/bridges.md."""
    group.add_argument("--token", help=f"shared secret clients must send (>= {MIN_TOKEN_CHARS} characters; needed "
                       f"beyond loopback). `ps` shows it: prefer --token-file or ${TOKEN_ENV_VAR}")
    group.add_argument("--token-file", type=Path, metavar="FILE", help="read the token from this file")
    group.add_argument("--allow-origin", action="append", default=[], metavar="ORIGIN",
                       help="also accept browser pages from this origin (e.g. http://localhost:3000); repeatable")


def server_token(args: argparse.Namespace) -> str | None:
    """The token from --token, --token-file or the environment (ws_access.token_from_sources)."""
    return token_from_sources(args.token, args.token_file)


def parse_host_port(value: str, flag: str) -> tuple[str, int]:
    host, separator, port = value.rpartition(":")
    if not separator or not port.isdigit() or not 0 < int(port) < 65536:
        raise UserError(f"{flag} wants HOST:PORT (e.g. 127.0.0.1:39539), got {value!r}")
    return host or "127.0.0.1", int(port)


def vmc_config(args: argparse.Namespace) -> VmcConfig:
    """--vmc HOST[:PORT] in the --vmc-role with its --vmc-bones (an Assistant sends the upper body by default)."""
    value = args.vmc if ":" in args.vmc else f"{args.vmc}:{DEFAULT_PORTS[args.vmc_role]}"
    host, port = parse_host_port(value, "--vmc")
    assistant = args.vmc_role == ASSISTANT
    spec = args.vmc_bones or ("upper" if assistant else "all")
    bones = BoneSelection.parse(spec, CANONICAL_WITH_HANDS).names
    return VmcConfig(host, port, send_rate=float(args.fps), viseme_names=viseme_names(args), bones=bones,
                     assistant=assistant)


def build_outputs(args: argparse.Namespace, session: GestureSession, clock: Clock) -> BridgeFanout:
    """The bridges the flags ask for, fanned out so that one failing output never stops the others."""
    bridges = []
    if args.avatar is not None and args.ws is None:
        raise UserError("--avatar sets the viewer's avatar: it goes with --ws PORT")
    if args.vmc:
        bridges.append(VmcBridge(vmc_config(args)))
    if args.osc:
        host, port = parse_host_port(args.osc, "--osc")
        bridges.append(OscBridge(OscConfig(host, port, send_rate=float(args.fps), coordinate_frame=args.osc_frame,
                                           viseme_names=viseme_names(args))))
    if args.ws is not None:
        config = WebSocketConfig(host=args.host, port=args.ws, token=server_token(args), fps=float(args.fps),
                                 style=session.controls.describe(), style_choices=tuple(session.bundle.styles.labels),
                                 body_parts=tuple(session.bundle.part_channels),
                                 allow_origins=tuple(args.allow_origin), avatar=resolve_avatar(args.avatar),
                                 lipsync=bool(viseme_names(args)), viseme_names=viseme_names(args) or
                                 WebSocketConfig.viseme_names, clock=clock.now)
        bridges.append(WebSocketBridge(config, on_control=session.controls.submit).start())
    if args.bvh is not None:
        bridges.append(BvhRecorder(args.bvh, fps=float(args.fps)))  # Frame Time of the output rate (60: upsampled)
    return BridgeFanout(bridges)
