"""serve --ray: today's protocol through Ray Serve replicas (a real local Ray cluster, loopback only).

Two replicas of one stream each: two streams land on different replicas (least-loaded), a third gets
today's 1013; streams equal plain ``serve``; scaling down drains running streams; a killed replica ends
only its own stream, with close code 1012 and a reason, and a reconnect works. Skipped when Ray is not
installed (``gesturecast[scale]``).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
from dataclasses import dataclass

import numpy as np
import pytest
from websockets.asyncio.client import connect
from websockets.exceptions import ConnectionClosed
from websockets.frames import CloseCode

from gesturecast.errors import UserError
from gesturecast.models.audio.files import SAMPLE_RATE, load_audio
from gesturecast.realtime.serve.cli_args import add_serve_arguments
from gesturecast.realtime.serve.ray_cli import (
    APP_NAME,
    AUTOSCALE_TARGET_FRACTION,
    REFUSAL_HEADROOM,
    ROUTE_PREFIX,
    add_ray_arguments,
    application,
    deployment_options,
)
from gesturecast.realtime.serve.ray_proxy import REPLICA_LOST_CODE, REPLICA_LOST_REASON
from gesturecast.realtime.serve.serve_command import build_server
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.tools.bench.serve_client import stream_audio

ray = pytest.importorskip("ray", reason="Ray Serve is the optional extra gesturecast[scale]")
serve = pytest.importorskip("ray.serve")

REPLICA_CPUS = 0.5  # two replicas and a redeploy's new one fit in the shared Ray's CPUs (tests/conftest.py)
STREAMS_PER_REPLICA = 1
CHUNK = 8000  # 0.5 s messages when streaming as fast as possible
PACED_CHUNK = 1600  # 100 ms messages at real-time pace
PACED_SECONDS = 4.0
EQUAL_SECONDS = 2.0  # compared with plain serve: the server releases frames in real time, twice per test
TIMEOUT_S = 90.0  # a broken deployment fails the test instead of hanging it
RECONNECT_TRIES = 30
RECONNECT_PAUSE_S = 1.0
STAGGER_S = 0.5  # streams connect this far apart: the router counts one before placing the next


def run(coroutine):
    return asyncio.run(asyncio.wait_for(coroutine, TIMEOUT_S))


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def serve_args(model, port: int, *flags: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_serve_arguments(parser)
    add_ray_arguments(parser)
    return parser.parse_args(["--ray", "--model", str(model), "--steps", "2", "--guidance", "1.5", "--seed", "0",
                              "--port", str(port), "--max-streams", str(STREAMS_PER_REPLICA),
                              "--replica-cpus", str(REPLICA_CPUS), *flags])


@dataclass
class ServeCluster:
    """The app deployed with ``args`` (2 replicas), its streams' ``url``, and how many replicas it has now."""

    args: argparse.Namespace
    url: str
    replicas: int

    def with_replicas(self, replicas: int, wait: bool = True) -> ServeCluster:
        """The app redeployed on ``replicas`` where it has another count (with ``wait``, until every one answers)."""
        if replicas != self.replicas:
            deploy(argparse.Namespace(**{**vars(self.args), "replicas": replicas}), self.url if wait else None)
            self.replicas = replicas
        return self


@pytest.fixture(scope="module")
def cluster(ray_cluster, tiny_model):
    """Serve on the run's local Ray (tests/conftest.py), its proxy on a free loopback port, and the app on 2
    replicas (a test that needs them asks for them again: the scale-down test leaves one); Serve is shut down after
    this module, Ray at the end of the run."""
    port = free_port()
    serve.start(http_options={"host": "127.0.0.1", "port": port})
    args = serve_args(tiny_model[1], port, "--replicas", "2")
    url = f"ws://127.0.0.1:{port}/stream/"
    deploy(args, url)
    try:
        yield ServeCluster(args, url, args.replicas)
    finally:
        serve.shutdown()


def deploy(args: argparse.Namespace, url: str | None = None) -> None:
    """Deploy (or update) the app; with ``url``, wait until Serve's proxy routes to every replica."""
    serve.run(application(args)[0], name=APP_NAME, route_prefix=ROUTE_PREFIX)
    if url is not None:
        assert run(every_replica_answers(url, args.replicas))


async def hold_a_stream(websocket) -> str:
    """``started`` once this connection holds its replica's stream slot (only started streams hold one), else the
    type of the refusal (``error``: the replica it reached is full)."""
    first = json.loads(await websocket.recv())
    if first["type"] != "hello":
        return first["type"]
    await websocket.send(json.dumps({"type": "start"}))
    return json.loads(await websocket.recv())["type"]


async def end_stream(websocket) -> None:
    """End a started stream and read until the server closes: its replica has let go of the stream by then."""
    with contextlib.suppress(ConnectionClosed):
        await websocket.send(json.dumps({"type": "end"}))
        async for _ in websocket:
            pass


async def every_replica_answers(url: str, replicas: int) -> bool:
    """Hold one started stream per replica (opened one after the other); True once all start, none gets a 1013."""
    for _ in range(RECONNECT_TRIES):
        async with contextlib.AsyncExitStack() as held:
            probes, kinds = [], []
            for index in range(replicas):
                probes.append(await held.enter_async_context(connect(f"{url}probe-{index}")))
                kinds.append(await hold_a_stream(probes[-1]))
            for websocket, kind in zip(probes, kinds, strict=True):
                if kind == "started":
                    await end_stream(websocket)
        if kinds == ["started"] * replicas:
            return True
        await asyncio.sleep(RECONNECT_PAUSE_S)
    return False


@pytest.fixture(scope="module")
def speech(shared_data):
    audio = load_audio(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")
    return [audio[(3 + 5 * i) * SAMPLE_RATE :][: int(PACED_SECONDS * SAMPLE_RATE)] for i in range(2)]


async def streams(url: str, audio: list[np.ndarray], chunk: int, paced: bool, starts: list[dict | None]) -> list:
    """Concurrent streams, connecting ``STAGGER_S`` apart."""
    async def one(index: int, samples: np.ndarray, start: dict | None):
        await asyncio.sleep(index * STAGGER_S)
        return await stream_audio(f"{url}s{index}", samples, chunk, paced=paced, start=start)

    return await asyncio.gather(*[one(i, a, s) for i, (a, s) in enumerate(zip(audio, starts, strict=True))])


def test_streams_through_two_replicas_equal_plain_serve(cluster, speech):
    args, url = cluster.args, cluster.with_replicas(2).url
    speech = [audio[: int(EQUAL_SECONDS * SAMPLE_RATE)] for audio in speech]
    starts = [{"seed": 1}, {"seed": 2, "style": "old", "guidance": 1.0}]
    through_ray = run(streams(url, speech, CHUNK, False, starts))  # one stream per replica, or one gets 1013
    plain = build_server(argparse.Namespace(**{**vars(args), "port": 0, "max_streams": 2}), MonotonicClock())
    try:
        alone = run(streams(plain.url, speech, CHUNK, False, starts))
    finally:
        plain.close()
    for ray_result, plain_result in zip(through_ray, alone, strict=True):
        assert ray_result.errors == [] and ray_result.stats["error"] is None
        assert ray_result.hello == plain_result.hello
        assert [m["type"] for m in ray_result.messages] == [m["type"] for m in plain_result.messages]
        np.testing.assert_array_equal(ray_result.poses(), plain_result.poses())


async def hold_and_overflow(url: str) -> tuple[list[str], dict, int]:
    """Two streams started and held open (one per replica), then a third connection: its reply and close code."""
    async with connect(f"{url}a") as first, connect(f"{url}b") as second:
        hellos = [await hold_a_stream(first), await hold_a_stream(second)]
        async with connect(f"{url}c") as third:
            refusal = json.loads(await third.recv())
            with pytest.raises(ConnectionClosed) as closed:
                await third.recv()
    return hellos, refusal, closed.value.rcvd.code


def test_full_replicas_refuse_a_new_stream_with_1013(cluster):
    started, refusal, code = run(hold_and_overflow(cluster.with_replicas(2).url))
    assert started == ["started", "started"]
    assert refusal == {"type": "error", "message": f"server full ({STREAMS_PER_REPLICA} streams)"}
    assert code == CloseCode.TRY_AGAIN_LATER


def replica_pids() -> list[int]:
    """Process ids of the app's live replicas, from Ray's actor table."""
    from ray._private import state  # the actor table with pids; ray.util.state needs the dashboard

    return [actor["Pid"] for actor in state.actors().values()
            if actor["ActorClassName"] == f"ServeReplica:{APP_NAME}:GestureReplica" and actor["State"] == "ALIVE"]


async def close_or_result(url: str, audio: np.ndarray, delay_s: float = 0.0):
    """The stream's result, or the close frame that ended it early (None: no close frame, 1006)."""
    await asyncio.sleep(delay_s)
    try:
        return await stream_audio(url, audio, PACED_CHUNK, paced=True)
    except ConnectionClosed as closed:
        return closed.rcvd


async def reconnect(url: str, audio: np.ndarray):
    """What a client does after losing its replica: try again until a stream goes through."""
    for _ in range(RECONNECT_TRIES):
        outcome = await close_or_result(url, audio)
        if hasattr(outcome, "stats") and outcome.stats is not None:
            return outcome
        await asyncio.sleep(RECONNECT_PAUSE_S)
    return None


def test_a_killed_replica_ends_only_its_own_stream_and_clients_can_reconnect(cluster, speech):
    url = cluster.with_replicas(2).url
    pids = replica_pids()
    assert len(pids) == 2

    async def kill_one_midway():
        running = [asyncio.ensure_future(close_or_result(f"{url}k{i}", a, i * STAGGER_S))
                   for i, a in enumerate(speech)]
        await asyncio.sleep(PACED_SECONDS / 4)
        os.kill(pids[0], signal.SIGKILL)
        outcomes = await asyncio.gather(*running)
        return outcomes, await reconnect(f"{url}again", speech[0][: CHUNK * 2])

    outcomes, again = run(kill_one_midway())
    closes = [(o.code, o.reason) for o in outcomes if not hasattr(o, "stats")]
    finished = [o for o in outcomes if hasattr(o, "stats")]
    assert closes == [(REPLICA_LOST_CODE, REPLICA_LOST_REASON)]  # each stream had its own replica: one was lost
    assert len(finished) == 1 and finished[0].stats["error"] is None
    assert len(finished[0].frames) == round(PACED_SECONDS * finished[0].hello["fps"])
    assert again is not None and again.errors == []


def test_scaling_down_lets_running_streams_finish(cluster, speech):
    """The module's last cluster test: it leaves one replica (a test after it would ask for two again)."""
    url = cluster.with_replicas(2).url
    assert run(every_replica_answers(url, 2))  # the previous tests' streams have left both, a killed one is back

    async def scale_down_midway():
        running = asyncio.ensure_future(streams(url, speech, PACED_CHUNK, True, [None, None]))
        await asyncio.sleep(PACED_SECONDS / 4)
        await asyncio.to_thread(cluster.with_replicas, 1, False)
        return await running

    results = run(scale_down_midway())
    for result, audio in zip(results, speech, strict=True):
        assert result.stats is not None and result.stats["error"] is None
        assert len(result.frames) == round(len(audio) / SAMPLE_RATE * result.hello["fps"])


def test_autoscaling_flags_become_ray_options(tiny_model):
    args = serve_args(tiny_model[1], free_port(), "--replicas", "1", "--max-replicas", "4", "--max-streams", "10")
    options = deployment_options(args)
    assert options["autoscaling_config"] == {"min_replicas": 1, "max_replicas": 4,
                                             "target_ongoing_requests": AUTOSCALE_TARGET_FRACTION * 10}
    assert options["max_ongoing_requests"] == 10 + REFUSAL_HEADROOM and "num_replicas" not in options
    with pytest.raises(UserError, match="--max-replicas"):
        deployment_options(argparse.Namespace(**{**vars(args), "replicas": 5}))


def test_bad_flags_fail_in_one_line_before_ray_starts(tiny_model):
    with pytest.raises(UserError, match="fixed --port"):
        application(serve_args(tiny_model[1], 0))
    with pytest.raises(UserError, match="token"):
        application(serve_args(tiny_model[1], free_port(), "--host", "0.0.0.0"))


def test_without_ray_the_command_names_the_extra():
    code = ("import sys; sys.modules['ray'] = None; from gesturecast.cli import main; "
            "sys.exit(main(['serve', '--ray', '--port', '18999']))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=TIMEOUT_S)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines()[-1].endswith("pip install 'gesturecast[scale]'")
    assert "Traceback" not in done.stderr


def test_a_serve_config_builds_the_same_application(tiny_model):
    from gesturecast.realtime.serve.ray_cli import app_builder

    flags = ["--model", str(tiny_model[1]), "--max-streams", "3", "--replicas", "2"]
    assert isinstance(app_builder({"flags": flags}), serve.Application)
    with pytest.raises(UserError, match="--max-replicas"):
        app_builder({"flags": [*flags, "--max-replicas", "1"]})
