"""bench serve --churn N --concurrency C --report-every K: short streams C at a time, RSS every K and idle RSS, as
JSON."""

import json

from gesturecast.cli import main
from gesturecast.tools.bench import serve

STREAMS = 6  # two reports, each client streams twice
REPORT_EVERY = 3
CONCURRENCY = 3
SETTLE_S = 0.1  # before each idle sample: what it reads is not checked here, only that it is there


def test_churn_reports_rss_every_k_streams_and_the_idle_rss(tiny_model, shared_data, capsys, monkeypatch):
    monkeypatch.setattr(serve, "CHURN_SETTLE_S", SETTLE_S)
    code = main(["bench", "serve", "--churn", str(STREAMS), "--concurrency", str(CONCURRENCY), "--json",
                 "--report-every", str(REPORT_EVERY),
                 "--model", str(tiny_model[1]), "--steps", "2",
                 "--audio", str(shared_data / "zeggs" / "067_Speech_2_x_1_0.wav")])
    churn = json.loads(capsys.readouterr().out)["churn"]
    assert code == 0 and churn["errors"] == [] and churn["active_streams_after"] == 0
    assert churn["concurrency"] == CONCURRENCY and churn["streams"] == STREAMS
    assert [s["streams"] for s in churn["rss_mib"]] == [0, REPORT_EVERY, STREAMS]
    assert set(churn["idle_rss_mib"]) == {"after_warmup", "end"} and churn["idle_end_minus_warmup_mib"] is not None
    assert churn["mib_per_100_streams_after_warmup"] is None  # too few streams after the warm-up for a slope


def test_churn_concurrency_is_bounded(tiny_model, capsys):
    code = main(["bench", "serve", "--churn", "50", "--concurrency", "0", "--model", str(tiny_model[1])])
    assert code == 2 and "--concurrency must be within 1..64" in capsys.readouterr().err


def test_churn_wants_at_least_one_report(tiny_model, capsys):
    code = main(["bench", "serve", "--churn", "5", "--report-every", "10", "--model", str(tiny_model[1])])
    assert code == 2 and "--churn wants at least --report-every (10) streams, got 5" in capsys.readouterr().err
