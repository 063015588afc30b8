"""Output flags: the VMC role picks the default port, the bones and whether the root is sent."""

import argparse

import pytest

from gesturecast.bridges.vmc_roles import HEAD_AND_LEGS
from gesturecast.errors import UserError
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS
from gesturecast.realtime.engine_setup import add_generation_arguments, add_output_arguments, vmc_config


def parse(*flags: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_generation_arguments(parser)
    add_output_arguments(parser)
    return parser.parse_args(list(flags))


def test_marionette_is_the_default_on_39539_with_every_bone_and_vrm0_visemes():
    config = vmc_config(parse("--vmc", "127.0.0.1"))
    assert (config.host, config.port, config.assistant) == ("127.0.0.1", 39539, False)
    assert config.bones == CANONICAL_WITH_HANDS.names and config.viseme_names == ("A", "I", "U", "E", "O")


def test_assistant_defaults_to_39540_and_the_upper_body():
    config = vmc_config(parse("--vmc", "10.0.0.2", "--vmc-role", "assistant", "--lipsync", "vrm1"))
    assert (config.host, config.port, config.assistant) == ("10.0.0.2", 39540, True)
    assert config.bones and not set(config.bones) & set(HEAD_AND_LEGS)
    assert config.viseme_names == ("aa", "ih", "ou", "ee", "oh")


def test_explicit_port_bones_and_lipsync_off():
    config = vmc_config(parse("--vmc", "host:40000", "--vmc-role", "assistant", "--vmc-bones", "none",
                              "--lipsync", "off"))
    assert (config.port, config.bones, config.viseme_names) == (40000, (), ())


def test_unknown_bone_is_a_user_error():
    with pytest.raises(UserError, match="Wing"):
        vmc_config(parse("--vmc", "127.0.0.1", "--vmc-bones", "Spine,Wing"))
