"""The VTuber recipes of README.md and docs/bridges.md, end to end: each command line runs (``live`` on a short
recording, as fast as it goes) with a VMC receiver on 39539 and one on 39540, as the apps listen, and what arrives
on which port is checked: the messages, the bones and the blend shapes each source owns."""

from __future__ import annotations

import shlex
import subprocess
import sys
import threading
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import pytest
import soundfile
from pythonosc.dispatcher import Dispatcher
from pythonosc.osc_server import BlockingOSCUDPServer

from gesturecast.bridges.vmc_roles import BoneSelection
from gesturecast.frames import FACE_NAMES, VISEME_NAMES
from gesturecast.models.audio.files import PACKAGED_SAMPLE, SAMPLE_RATE, load_audio
from gesturecast.models.motion.skeleton import CANONICAL_WITH_HANDS as SKELETON

REPO = Path(__file__).resolve().parents[2]
PORTS = (39539, 39540)  # a Marionette's and a Performer's customary VMC ports
SPEECH_SECONDS = 2
WHOLE_AVATAR = ("/VMC/Ext/Root/Pos", "/VMC/Ext/OK", "/VMC/Ext/T")  # what only the avatar's owner sends


@dataclass(frozen=True)
class Recipe:
    port: int  # where the app listens
    bones: str  # the --vmc-bones preset that arrives
    whole_avatar: bool  # root, availability, time, blinks and mood too


RECIPES = {  # the command lines as README.md and docs/bridges.md give them
    "gesturecast live --vmc 127.0.0.1:39539": Recipe(39539, "all", True),
    "gesturecast live --vmc 127.0.0.1:39539 --vmc-role assistant": Recipe(39539, "upper", False),
    "gesturecast live --vmc 127.0.0.1:39540 --vmc-role assistant --vmc-bones arms": Recipe(39540, "arms", False),
}


class VmcReceiver:
    """A VMC receiver on ``port`` (python-osc, as the apps' receivers decode it): the messages by address."""

    def __init__(self, port: int) -> None:
        dispatcher = Dispatcher()
        dispatcher.set_default_handler(self._received)
        self.messages: dict[str, list[tuple]] = defaultdict(list)
        self.server = BlockingOSCUDPServer(("127.0.0.1", port), dispatcher)
        self.thread = threading.Thread(target=self.server.serve_forever, daemon=True)
        self.thread.start()

    def _received(self, address: str, *arguments) -> None:
        self.messages[address].append(arguments)

    def names(self, address: str) -> set[str]:
        """The first argument (a bone's or a blend shape's name) of every ``address`` message."""
        return {arguments[0] for arguments in self.messages[address]}

    def close(self) -> None:
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture(scope="module")
def receivers():
    opened = []
    try:
        for port in PORTS:
            opened.append(VmcReceiver(port))
    except OSError as error:
        for receiver in opened:
            receiver.close()
        pytest.skip(f"a VMC port is taken on this machine ({error})")
    yield dict(zip(PORTS, opened, strict=True))
    for receiver in opened:
        receiver.close()


@pytest.fixture(scope="module")
def speech(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("recipes") / "talk.wav"
    soundfile.write(path, load_audio(PACKAGED_SAMPLE)[: SPEECH_SECONDS * SAMPLE_RATE], SAMPLE_RATE)
    return path


@pytest.mark.parametrize("command", RECIPES)
def test_every_recipe_in_the_docs_is_written_as_tested(command):
    assert command in (REPO / "README.md").read_text() and command in (REPO / "docs" / "bridges.md").read_text()


@pytest.mark.parametrize("command", RECIPES)
def test_each_recipe_sends_its_bones_and_blend_shapes_to_the_port_its_app_listens_on(command, receivers, speech):
    recipe = RECIPES[command]
    for receiver in receivers.values():
        receiver.messages.clear()
    argv = [*shlex.split(command)[1:], "--input", str(speech), "--pace", "fast", "--gestures", "off"]
    result = subprocess.run([sys.executable, "-m", "gesturecast.cli", *argv], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    app, other = receivers[recipe.port], receivers[next(port for port in PORTS if port != recipe.port)]
    assert not other.messages  # nothing to the port the app does not listen on
    assert app.names("/VMC/Ext/Bone/Pos") == set(BoneSelection.parse(recipe.bones, SKELETON).names)
    blend_shapes = app.names("/VMC/Ext/Blend/Val")
    assert set(VISEME_NAMES["vrm0"]) <= blend_shapes  # the mouth: A I U E O, the default --lipsync vrm0
    assert bool(blend_shapes & set(FACE_NAMES["vrm0"])) == recipe.whole_avatar  # blinks and mood
    assert all(bool(app.messages[address]) == recipe.whole_avatar for address in WHOLE_AVATAR)
