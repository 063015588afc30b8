"""bench serve: against a server it did not start (--url, as for serve --ray), and its own server with the clients in
another process."""

import json

from gesturecast.cli import main
from gesturecast.models.runtime.bundle import ModelBundle
from gesturecast.realtime.serve.server import GestureServer, ServeConfig
from gesturecast.realtime.serve.setup import StreamSessions
from gesturecast.realtime.timing.clock import MonotonicClock
from gesturecast.settings import Settings

STREAMS = 2
SECONDS = 2.0
FPS = 30
MARGIN_MS = 100.0


def test_bench_serve_measures_a_running_server(tiny_model, shared_data, capsys, wait_until):
    bundle = ModelBundle.load(tiny_model[1])
    clock = MonotonicClock()
    sessions = StreamSessions(Settings(steps=2, guidance=1.5, seed=0, audio_guidance=1.0, smoothing=0, gestures=None,
                                       margin_ms=MARGIN_MS), bundle, clock, max_streams=STREAMS)
    server = GestureServer(sessions, clock, ServeConfig(port=0, max_streams=STREAMS)).start()
    try:
        code = main(["bench", "serve", "--url", server.url, "--streams", str(STREAMS), "--seconds", str(SECONDS),
                     "--audio", str(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav"), "--json"])
        assert wait_until(lambda: server.active_streams() == 0)  # the server records a stream as it closes it
        served = {s["stream"] for s in server.finished}
    finally:
        server.close()
    assert code == 0
    run = json.loads(capsys.readouterr().out)["runs"][0]
    assert run["url"] == server.url and run["batching"] is None
    assert run["frames"] == STREAMS * SECONDS * FPS and run["errors"] == [] and run["missing_stats"] == 0
    assert served == {f"bench-{i}" for i in range(STREAMS)}  # the clients streamed to that server
    assert run["client_end_to_end_ms"]["p95"] > 0


def test_bench_serve_runs_its_clients_in_another_process_and_counts_their_cpu_apart(tiny_model, shared_data, capsys):
    code = main(["bench", "serve", "--model", str(tiny_model[1]), "--steps", "2", "--streams", str(STREAMS),
                 "--seconds", str(SECONDS), "--audio", str(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav"), "--json"])
    assert code == 0
    run = json.loads(capsys.readouterr().out)["runs"][0]
    assert run["frames"] == STREAMS * SECONDS * FPS and run["errors"] == [] and run["missing_stats"] == 0
    assert run["rtf"] > 0 and run["client_rtf"] > 0  # the server's CPU and the clients' (another process), apart
    assert run["server_mb"]["peak"] >= run["server_mb"]["idle"] > 0


def test_bench_serve_measures_worker_processes(tiny_model, shared_data, capsys):
    speech = shared_data / "zeggs" / "067_Speech_2_x_1_0.wav"
    code = main(["bench", "serve", "--workers", "2", "--model", str(tiny_model[1]), "--steps", "2", "--streams",
                 str(STREAMS), "--seconds", str(SECONDS), "--audio", str(speech), "--client-niceness", "10", "--json"])
    assert code == 0
    result = json.loads(capsys.readouterr().out)
    assert result["settings"]["client_niceness"] == 10
    run = result["runs"][0]
    assert run["workers"] == 2 and run["frames"] == STREAMS * SECONDS * FPS and run["errors"] == []
    assert run["streams_per_worker"] == [1, 1]  # dealt to the worker with fewest, not hashed by the kernel
    assert run["rtf"] > 0 and run["client_rtf"] > 0  # the workers' CPU from /proc, the clients' apart
    assert run["server_mb"]["peak"] >= run["server_mb"]["idle"] > 0


def test_bench_serve_refuses_a_niceness_out_of_range(tiny_model, capsys):
    assert main(["bench", "serve", "--model", str(tiny_model[1]), "--client-niceness", "20"]) != 0
    assert "--client-niceness must be within 0..19" in capsys.readouterr().err
