"""Sessions for ``gesturecast serve``: every stream's generator shares one batched denoiser session."""

from __future__ import annotations

from dataclasses import replace

from gesturecast.bridges.control import ControlError
from gesturecast.errors import UserError
from gesturecast.models.motion.root_anchor import RootMode
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.generation.generator import Generator, GeneratorSettings
from gesturecast.realtime.pose.session import GestureSession, SessionConfig
from gesturecast.realtime.run.engine_setup import setting_budget
from gesturecast.realtime.serve.batched_denoiser import DenoiserBatcher, SharedDenoiserBundle
from gesturecast.realtime.serve.protocol import StreamOptions
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.latency import LatencyBudget
from gesturecast.settings import LATENCY_SETTINGS


class StreamSessions:
    """Builds one :class:`GestureSession` per stream from a ``start`` message over the server's defaults.

    Sessions share the server's budget L unless their ``start`` names a latency setting (its look-ahead and
    margin, the server's smoothing), and one :class:`DenoiserBatcher`; each has its own generator state
    (KV cache rows, RNG, decoder, features). Close with :meth:`close`.
    """

    def __init__(self, bundle: ModelBundle, defaults: GeneratorSettings, budget: LatencyBudget, clock: Clock,
                 max_streams: int, session_defaults: SessionConfig | None = None) -> None:
        self.defaults = defaults
        self.session_defaults = session_defaults or SessionConfig()
        self.budget = budget
        self.clock = clock
        self.batcher = DenoiserBatcher(bundle.path("denoiser"), defaults.threads, max_waiting=max_streams).start()
        self.bundle = SharedDenoiserBundle.wrap(bundle, self.batcher)

    @property
    def gesture_names(self) -> tuple[str, ...]:
        """The lexicon's gestures every stream may be asked for (gesture controls)."""
        return tuple(clip.name for clip in self.session_defaults.gesture_clips)

    def budget_for(self, options: StreamOptions) -> LatencyBudget:
        """The stream's L: the server's, or the one of the ``start`` message's latency setting."""
        if options.latency is None:
            return self.budget
        return setting_budget(LATENCY_SETTINGS[options.latency], self.bundle, self.budget.smoothing_frames)

    def settings(self, options: StreamOptions) -> GeneratorSettings:
        chosen = {
            "style": options.style,
            "second_style": options.second_style,
            "part_styles": options.part_styles,
            "gamma": options.gamma,
            "style_strength": options.style_strength,
            "guidance": options.guidance,
            "audio_guidance": options.audio_guidance,
            "seed": options.seed,
        }
        settings = replace(self.defaults, **{name: value for name, value in chosen.items() if value is not None})
        return replace(settings, lookahead=self.budget_for(options).lookahead_frames)

    def session(self, options: StreamOptions) -> GestureSession:
        """A fresh session; ControlError (sent to the client) for a style the model does not know or a latency
        setting it cannot serve."""
        try:
            generator = Generator(self.bundle, self.settings(options))
        except UserError as error:
            raise ControlError(str(error)) from None
        config = self.session_defaults
        if options.root is not None:
            config = replace(config, root_mode=RootMode(options.root))
        return GestureSession(self.bundle, generator, self.budget_for(options), self.clock, config)

    def close(self) -> None:
        self.batcher.close()
