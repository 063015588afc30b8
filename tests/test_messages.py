"""Messages that point the right way: the argument that was wrong, in the words the user typed; a Motion that prints
in one line; ``help(gesturecast.generate)`` with what it returns and an example."""

from __future__ import annotations

import numpy as np
import pytest

import gesturecast
from gesturecast.api import Motion
from gesturecast.bridges.transport import UdpSender, UdpTarget
from gesturecast.errors import UserError
from gesturecast.realtime.engine_cli import osc_in_address


def test_settings_given_in_the_sample_rate_place_say_to_pass_them_by_name():
    with pytest.raises(UserError, match=r"pass settings by name: generate\(audio, settings=Settings"):
        gesturecast.generate("talk.wav", gesturecast.Settings(style="old"))


def test_osc_in_errors_quote_what_was_typed():
    assert osc_in_address("9001") == ("127.0.0.1", 9001) and osc_in_address(None) is None
    with pytest.raises(UserError, match=r"--osc-in wants a port .*; got '70000'$"):
        osc_in_address("70000")


def test_an_unresolvable_vmc_host_names_the_vmc_flag():
    with pytest.raises(UserError, match=r"VMC: cannot resolve nohost\.invalid:39539 .*given to --vmc$"):
        UdpSender(UdpTarget("nohost.invalid", 39539), "VMC")


def test_a_motion_prints_in_one_short_line():
    frames = 45
    motion = Motion(rotations=np.zeros((frames, 52, 4)), root_positions=np.zeros((frames, 3)),
                    bone_names=tuple(f"b{i}" for i in range(52)), fps=30.0, visemes=None, viseme_names=(),
                    speaking=np.zeros(frames, bool), frames=())
    assert repr(motion) == "Motion(45 frames at 30 fps = 1.50 s, 52 bones, visemes off, face off)"


def test_the_generate_docstring_says_what_it_returns_with_an_example_and_no_repository_paths():
    doc = gesturecast.generate.__doc__
    assert "Returns:" in doc and "Example::" in doc and "motion.save(" in doc and "docs/" not in doc
