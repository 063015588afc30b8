"""``gesturecast bench cues`` runs and prints its JSON: words placed and the per-latent costs per word count."""

import json


def test_bench_cues_prints_the_comparison_as_json(cli_here):
    result = cli_here("bench", "cues", "--words", "10", "2000")
    assert result.returncode == 0, result.stderr[-2000:]
    report = json.loads(result.stdout)
    assert [r["words"] for r in report["results"]] == [10, 2000]
    assert [r["placed"] for r in report["results"]] == [1, 200]  # every 10th word a trigger, 5 s apart
    for row in report["results"]:
        assert row["push_ms_per_latent"]["p50"] > 0 and row["plan_us_per_latent"]["p95"] >= 0
