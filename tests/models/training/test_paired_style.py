"""--paired-style: every take with speech trains under one label; the others keep their own."""

import pytest

from gesturecast.errors import UserError
from gesturecast.models.training.arrays import training_style
from gesturecast.models.training.presets import get_preset


def test_takes_with_speech_train_under_the_paired_label():
    conversation = {"style": "conversation"}
    assert training_style(conversation, has_audio=True, paired_style="speech") == "speech"
    assert training_style(conversation, has_audio=False, paired_style="speech") == "neutral"
    assert training_style(conversation, has_audio=True, paired_style="") == "neutral"


def test_an_unknown_paired_label_is_refused_before_training():
    assert get_preset("tiny", paired_style="speech").paired_style == "speech"
    with pytest.raises(UserError, match="unknown style 'oration'"):
        get_preset("tiny", paired_style="oration")
