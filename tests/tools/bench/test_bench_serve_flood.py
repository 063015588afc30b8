"""bench serve --flood: one client floods words messages beside a measured stream; it is refused, its stream goes on,
and the server's log lines are counted."""

import json
import subprocess
import sys

from gesturecast.cli import main
from gesturecast.tools.bench.serve_client import ClientResult, words_message
from gesturecast.tools.bench.serve_flood import LogLines, flood_summary, stream_lateness

SECONDS = 2.0
FPS = 30


def test_flooder_is_refused_and_its_stream_and_the_measured_one_go_on(tiny_model, shared_data, capsys):
    code = main(["bench", "serve", "--model", str(tiny_model[1]), "--steps", "2", "--streams", "1", "--flood",
                 "--seconds", str(SECONDS), "--audio", str(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav"), "--json"])
    assert code == 0
    run = json.loads(capsys.readouterr().out)["runs"][0]
    assert run["streams"] == 1 and len(run["per_stream"]) == 1 and run["errors"] == []
    assert run["frames"] == SECONDS * FPS  # the measured stream only
    flooder = run["flooder"]
    assert flooder["messages_sent"] > flooder["refused_rate_limited"] > 0
    assert flooder["server_rate_limited_messages"] == flooder["refused_rate_limited"]  # each refusal was told
    assert flooder["frames_received"] == SECONDS * FPS  # its own stream went on
    assert set(run["server_log_lines"]) == {"lines", "max_per_second", "per_second"}


def test_log_lines_counts_what_child_processes_write_to_standard_error():
    with LogLines() as logs:
        subprocess.run([sys.executable, "-c", "import sys; sys.stderr.write('a\\nb\\nc\\n')"], check=True)
    assert logs.lines == 3 and logs.max_per_second == 3


def test_lateness_and_flood_summaries_from_the_messages():
    stats = {"frames": 200, "deadline_misses": 3, "latency_budget_ms": 500.0, "end_to_end_ms": {"p95": 512.5},
             "rate_limited_messages": 2}
    assert stream_lateness(stats) == {"frames": 200, "late_pct": 1.5, "p95_over_budget_ms": 12.5}
    flooder = ClientResult(hello={}, messages=[{"type": "ack"}, {"type": "error", "message": "rate limit: at most"},
                                               {"type": "error", "message": "rate limit: at most"},
                                               {"type": "error", "message": "no such gesture"}], stats=stats)
    flooder.flood_sent = 3
    summary = flood_summary(flooder)
    assert (summary["refused_rate_limited"], summary["applied"], summary["other_errors"]) == (2, 1, 1)


def test_a_flood_message_carries_the_words_asked_in_stream_order():
    words = json.loads(words_message(500, 2.0))["words"]
    assert len(words) == 500 and words[0]["start"] == 2.0
    assert all(a["end"] == b["start"] for a, b in zip(words, words[1:], strict=False))
