"""Sessions and their outputs from :class:`Settings` and :class:`Outputs`: :class:`SessionFactory` is the one way a
session is made, by every door (the library's ``generate`` and ``Stream``, live, generate, batch, serve, the Pipecat
processor, the benchmarks).

A latency setting is resolved once per factory, by :func:`resolve_latency`, into one :class:`LatencyBudget`
(look-ahead δ, compute margin, smoothing k, hence L); the generator hears that δ and the session presents at that L.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from gesturecast.bridges.avatar_file import resolve_avatar
from gesturecast.bridges.bvh_recorder import BvhRecorder
from gesturecast.bridges.fanout import BridgeFanout
from gesturecast.bridges.osc import OscBridge, OscConfig
from gesturecast.bridges.output_settings import Outputs, parse_host_port
from gesturecast.bridges.vmc import VmcBridge, VmcConfig
from gesturecast.bridges.vmc_roles import BoneSelection
from gesturecast.bridges.ws_access import token_from_sources
from gesturecast.errors import UserError
from gesturecast.models.generator.diffusion import SamplerConfig
from gesturecast.models.generator.style_prompt import StylePrompt
from gesturecast.models.motion.root_anchor import RootMode
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.models.style.params import DEFAULT_STYLE_PARAMS, StyleBook
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.gestures.director import GestureDirector
from gesturecast.realtime.gestures.repertoire import GestureRepertoire, load_repertoire
from gesturecast.realtime.pose.seed_motion import load_seed_motion
from gesturecast.realtime.pose.session import GestureSession, SessionConfig
from gesturecast.realtime.pose.style_hearing import StyleHearing, StyleState
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.latency import LatencyBudget
from gesturecast.settings import LATENCY_SETTINGS, LatencySetting, Settings

if TYPE_CHECKING:  # the WebSocket server (and asyncio) load only where one runs: `generate` never needs them
    from gesturecast.bridges.websocket_server import WebSocketConfig

def load_bundle(path: Path) -> ModelBundle:
    if not (path / "model.json").is_file():
        raise UserError(f"no model bundle at {path} (expected model.json); train one with `gesturecast train`")
    return ModelBundle.load(path)


def resolve_latency(settings: Settings, bundle: ModelBundle) -> LatencyBudget:
    """The latency setting (with ``lookahead`` / ``margin_ms`` overriding it) on this model: δ, margin, k → L."""
    return setting_budget(LATENCY_SETTINGS[settings.latency], bundle, settings.smoothing, settings.lookahead,
                          settings.margin_ms)


def setting_budget(setting: LatencySetting, bundle: ModelBundle, smoothing: int, lookahead: int | None = None,
                   margin_ms: float | None = None) -> LatencyBudget:
    """A latency dial position on this model (its look-ahead capped at the model's δa), smoothing k frames."""
    lookahead = setting.lookahead_for(bundle.audio_lookahead) if lookahead is None else lookahead
    margin = setting.compute_margin_ms if margin_ms is None else margin_ms
    return LatencyBudget(bundle.frames_per_latent, lookahead, margin, smoothing_frames=smoothing)


def style_hearing(settings: Settings, bundle: ModelBundle) -> StyleHearing:
    """What the generator hears of the styles asked: the stylizer after it gives the style (docs/stylizer.md), so it
    hears a label it learned with speech, ``settings.generator_style``, and the model's labels the stylizer does not
    give (the paired speech takes' styles) as asked, so that the motion follows the voice in every style
    (docs/voices.md)."""
    return StyleHearing(StylePrompt("label", settings.generator_style),
                        StyleBook.labels_left(DEFAULT_STYLE_PARAMS, bundle.styles.labels))


def generator_settings(settings: Settings, bundle: ModelBundle, budget: LatencyBudget,
                       hearing: StyleHearing | None = None) -> GeneratorSettings:
    """DDIM with K steps (the settings', else the model's), or DDPM over all T steps of the model's schedule (the
    offline-quality path), hearing the budget's look-ahead and what ``hearing`` (default :func:`style_hearing`) makes
    of the styles asked."""
    steps = (settings.steps or bundle.default_steps) if settings.sampler == "ddim" else \
        bundle.denoiser_config.num_timesteps
    hearing = style_hearing(settings, bundle) if hearing is None else hearing
    heard = hearing.heard(style_state(settings))
    return GeneratorSettings(
        sampler=SamplerConfig(settings.sampler, steps),
        guidance=settings.guidance,
        style_strength=heard.strength,
        style=heard.style,
        second_style=heard.second_style,
        gamma=heard.gamma,
        seed=settings.seed,
        threads=settings.threads,
        audio_guidance=settings.audio_guidance,
        lookahead=budget.lookahead_frames,
        part_styles=heard.part_styles,
    )


def session_config(settings: Settings, bundle: ModelBundle) -> SessionConfig:
    """What a session of these settings needs besides its generator and gestures: root mode, seed motion, lip sync,
    face, gesture size and pause."""
    seed = None if settings.seed_motion is None else load_seed_motion(settings.seed_motion, bundle)
    return SessionConfig(root_mode=RootMode(settings.root), seed_motion=seed, lipsync=settings.lipsync,
                         face=settings.face, intensity=settings.intensity, paused=settings.pause,
                         style=style_state(settings), hearing=style_hearing(settings, bundle))


def style_state(settings: Settings) -> StyleState:
    """The style a stream of these settings starts in: the session's controls own it from then on."""
    return StyleState(settings.style_prompt(), settings.second_style(), settings.gamma, settings.part_styles,
                      settings.style_strength)


class SessionFactory:
    """Sessions of one model from :class:`Settings`, each with its generator and its gestures
    (:class:`GestureDirector`). What the sessions share is made once: the bundle (loaded from ``settings.model``
    unless given, e.g. a batch worker's or the server's shared-denoiser bundle), the seed motion and the gesture
    repertoire of ``settings`` (unless given: one already loaded for the same lexicon, style label, seed and bundle,
    as a benchmark's runs share), and the latency budget of each latency setting asked for."""

    def __init__(self, settings: Settings, bundle: ModelBundle | None = None,
                 repertoire: GestureRepertoire | None = None) -> None:
        self.settings = settings
        self.bundle = load_bundle(settings.model) if bundle is None else bundle
        self.config = session_config(settings, self.bundle)
        self.repertoire = load_repertoire(settings, self.bundle) if repertoire is None else repertoire
        self._budgets: dict[tuple, LatencyBudget] = {}

    def budget(self, settings: Settings | None = None) -> LatencyBudget:
        """L of ``settings`` (default the factory's) on this model, resolved once per latency setting."""
        settings = self.settings if settings is None else settings
        key = (settings.latency, settings.lookahead, settings.margin_ms, settings.smoothing)
        if key not in self._budgets:
            self._budgets[key] = resolve_latency(settings, self.bundle)
        return self._budgets[key]

    def generator(self, settings: Settings | None = None) -> Generator:
        """A fresh generator of ``settings`` (default the factory's): UserError for a style, body part or look-ahead
        the model does not serve."""
        settings = self.settings if settings is None else settings
        generator = Generator(self.bundle, generator_settings(settings, self.bundle, self.budget(settings)))
        for prompt in style_state(settings).prompts():  # each style asked is embedded: one the model cannot use is
            generator.styles.embed(prompt)  # refused here, also where the generator hears another
        return generator

    def session(self, clock: Clock, settings: Settings | None = None) -> GestureSession:
        """A fresh session. ``settings`` (default the factory's) may change what one stream chooses (the style
        settings, seed, latency, root, gesture size, pause); the seed motion and the gesture repertoire stay the
        factory's."""
        settings = self.settings if settings is None else settings
        config = replace(self.config, root_mode=RootMode(settings.root), intensity=settings.intensity,
                         paused=settings.pause, style=style_state(settings),
                         hearing=style_hearing(settings, self.bundle))
        budget = self.budget(settings)
        gestures = GestureDirector(self.repertoire, self.bundle.frames_per_latent / self.bundle.feature_config.fps,
                                   budget.total_s)
        return GestureSession(self.bundle, self.generator(settings), budget, clock, config, gestures=gestures)


def build_session(settings: Settings, clock: Clock, bundle: ModelBundle | None = None) -> GestureSession:
    """One session with these settings (a :class:`SessionFactory` used once)."""
    return SessionFactory(settings, bundle).session(clock)


def vmc_config(outputs: Outputs, settings: Settings) -> VmcConfig:
    """VMC to ``outputs.vmc`` in its role with its bones (an Assistant sends the upper body by default, and no
    blinks or expressions: the Performer's face tracking keeps the eyes and the face)."""
    host, port = outputs.vmc_address()
    bones = BoneSelection.parse(outputs.vmc_bone_spec(), CANONICAL_WITH_HANDS).names
    return VmcConfig(host, port, send_rate=float(settings.fps), viseme_names=settings.lipsync_names,
                     face_names=() if outputs.assistant else settings.face_names, bones=bones,
                     assistant=outputs.assistant)


def websocket_config(outputs: Outputs, settings: Settings, session: GestureSession, clock: Clock) -> WebSocketConfig:
    from gesturecast.bridges.websocket_server import WebSocketConfig  # asyncio loads only where a server runs

    token = token_from_sources(outputs.token, outputs.token_file)
    return WebSocketConfig(host=outputs.host, port=outputs.ws, token=token, fps=float(settings.fps),
                           style=session.controls.describe(), style_choices=tuple(session.bundle.styles.labels),
                           body_parts=tuple(session.bundle.part_channels), gestures=session.gestures.names,
                           allow_origins=outputs.allow_origins,
                           avatar=resolve_avatar(outputs.avatar), lipsync=bool(settings.lipsync_names),
                           viseme_names=settings.lipsync_names or WebSocketConfig.viseme_names,
                           face_names=settings.face_names, clock=clock.now)


def build_outputs(outputs: Outputs, settings: Settings, session: GestureSession, clock: Clock) -> BridgeFanout:
    """The bridges ``outputs`` asks for, fanned out so that one failing output never stops the others."""
    bridges = []
    try:
        if outputs.vmc:
            bridges.append(VmcBridge(vmc_config(outputs, settings)))
        if outputs.osc:
            host, port = parse_host_port(outputs.osc, "osc")
            bridges.append(OscBridge(OscConfig(host, port, send_rate=float(settings.fps),
                                               coordinate_frame=outputs.osc_frame,
                                               viseme_names=settings.lipsync_names,
                                               face_names=settings.face_names)))
        if outputs.ws is not None:
            from gesturecast.bridges.websocket_server import WebSocketBridge

            config = websocket_config(outputs, settings, session, clock)
            bridges.append(WebSocketBridge(config, on_control=session.controls.submit).start())
        if outputs.bvh is not None:
            bridges.append(BvhRecorder(outputs.bvh, fps=float(settings.fps)))  # Frame Time of the output rate
    except BaseException:
        BridgeFanout(bridges).close()  # a later output failing (a port in use) leaves no earlier one open
        raise
    return BridgeFanout(bridges)
