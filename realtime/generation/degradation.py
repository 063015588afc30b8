"""The rungs of the degradation ladder (:mod:`gesturecast.realtime.timing.ladder`): the work a latent is generated
with when the last ones used most of their compute margin.

Each rung keeps what the rungs above it dropped and drops one more piece of work, cheapest in following per
millisecond saved first (the measurements are in docs/latency.md "Degradation ladder"):

0. full work, as the settings ask;
1. one DDIM step per latent (K → 1): about 0.4 ms of the default's 1.9 ms of denoiser and decoder per latent;
2. and no audio guidance (s_a → 1): the audio-null row of every denoiser call is gone, about 0.1 ms more.

Stepping down to rung 1 changes no denoiser row, so it costs nothing on the latent that is already late; rung 2
drops a row, and climbing back from it recomputes the audio-null row's cache (a few ms, with slack).

A rung does what a user could also ask for (``--audio-guidance 1``, ``--steps 1``), so what a rung costs in
following is what ``bench voices`` measures with those flags. The generator's settings stay as asked while it
runs on a rung (:meth:`gesturecast.realtime.generation.generator.Generator.degrade`), so a live control that
changes them is kept, and rung 0 is exactly the work asked.
"""

from __future__ import annotations

from typing import NamedTuple


class Rung(NamedTuple):
    name: str
    audio_guidance: bool  # keep the audio-null row (s_a as set)
    steps: int | None  # at most this many DDIM steps per latent (None: as set)


RUNGS = (
    Rung("full", audio_guidance=True, steps=None),
    Rung("one DDIM step", audio_guidance=True, steps=1),
    Rung("one DDIM step, no audio guidance", audio_guidance=False, steps=1),
)
