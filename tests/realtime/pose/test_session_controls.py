"""The session's controls: a flood of gestures that the full cue plan refuses is logged once per interval."""

import logging
from types import SimpleNamespace

from gesturecast.controls import Gesture
from gesturecast.realtime.generation.generator import GeneratorSettings
from gesturecast.realtime.gestures.cues import CueRefused
from gesturecast.realtime.pose.session_controls import SessionControls


class FullPlan:
    """A stream's gestures whose plan is full once the controls are applied (checks pass, the cue is refused)."""

    names = ("wave",)

    def check_gesture(self, name):
        pass

    def stroke_lead_s(self):
        return 0.5

    def cue_gesture(self, name, t):
        raise CueRefused("the stream already holds 256 gestures to come")


def test_a_flood_of_refused_gesture_controls_writes_one_line(caplog, monkeypatch):
    monkeypatch.setattr("gesturecast.log_throttle.time", SimpleNamespace(monotonic=lambda: 0.0))  # one interval
    settings = GeneratorSettings(audio_guidance=1.5)
    controls = SessionControls(SimpleNamespace(base_guidance=1.5, settings=settings), root=None, gestures=FullPlan())
    with caplog.at_level(logging.WARNING):
        for latent in range(100):  # a gesture per OSC packet, each applied at its latent
            controls.submit((Gesture("wave"),))
            controls.advance(latent * 0.133)
    assert len([r for r in caplog.records if "gesture cues not kept" in r.getMessage()]) == 1
