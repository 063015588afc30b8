"""Sessions for ``gesturecast serve``: every stream's generator shares one batched denoiser session."""

from __future__ import annotations

from gesturecast.controls import ControlError
from gesturecast.errors import UserError
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.pose.session import GestureSession
from gesturecast.realtime.run.engine_setup import SessionFactory
from gesturecast.realtime.serve.batched_denoiser import DenoiserBatcher, SharedDenoiserBundle
from gesturecast.realtime.serve.protocol import StreamOptions
from gesturecast.realtime.timing.clock import Clock
from gesturecast.realtime.timing.latency import LatencyBudget
from gesturecast.settings import Settings


class StreamSessions:
    """One :class:`GestureSession` per stream, from a ``start`` message over the server's default settings, made by
    the :class:`SessionFactory` of the server's model whose denoiser is one :class:`DenoiserBatcher` for all
    streams; each session has its own generator state (KV cache rows, RNG, decoder, features). Sessions share the
    server's budget L unless their ``start`` names a latency setting (its look-ahead and margin, the server's
    smoothing; resolved once per setting). Close with :meth:`close`.
    """

    def __init__(self, defaults: Settings, bundle: ModelBundle, clock: Clock, max_streams: int) -> None:
        self.defaults = defaults
        self.clock = clock
        self.batcher = DenoiserBatcher(bundle.path("denoiser"), defaults.threads, max_waiting=max_streams).start()
        self.factory = SessionFactory(defaults, SharedDenoiserBundle.wrap(bundle, self.batcher))
        self.bundle = self.factory.bundle

    @property
    def budget(self) -> LatencyBudget:
        """The server's L (of the default settings)."""
        return self.factory.budget()

    @property
    def gesture_names(self) -> tuple[str, ...]:
        """The lexicon's gestures every stream may be asked for (gesture controls)."""
        return self.factory.repertoire.names

    def settings(self, options: StreamOptions) -> Settings:
        """The server's defaults with what the ``start`` message chose (a latency setting replaces the server's
        look-ahead and margin)."""
        settings = self.defaults.with_style(options.style)
        if options.seed is not None:
            settings = settings.replace(seed=options.seed)
        if options.latency is not None:
            settings = settings.replace(latency=options.latency, lookahead=None, margin_ms=None)
        return settings

    def session(self, options: StreamOptions) -> GestureSession:
        """A fresh session; ControlError (sent to the client) for a style the model does not know or a latency
        setting it cannot serve."""
        try:
            return self.factory.session(self.clock, self.settings(options))
        except UserError as error:
            raise ControlError(str(error)) from None

    def close(self) -> None:
        self.batcher.close()
