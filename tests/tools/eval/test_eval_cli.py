"""`gesturecast eval --quick` on the tiny trained bundle: every system and metric key, deltas, plots."""

import json

import pytest

from gesturecast.cli import main
from gesturecast.tools.eval.metrics import METRIC_KEYS
from gesturecast.tools.eval.suite import SYSTEM_NAMES


@pytest.fixture(scope="module")
def quick_report(tiny_model, shared_data, tmp_path_factory):
    _, bundle = tiny_model
    out = tmp_path_factory.mktemp("eval") / "results.json"
    cache = bundle.parent / "dataset"
    unseen = shared_data / "speech" / "tts_01_en-us.wav"
    code = main(["eval", "--json", str(out), "--model", str(bundle), "--quick", "--cache", str(cache),
                 "--unseen", str(unseen), "--ddpm-seconds", "1"])
    assert code == 0
    return out, json.loads(out.read_text())


def test_every_system_has_every_metric(quick_report):
    _, report = quick_report
    assert tuple(report["systems"]) == SYSTEM_NAMES
    for name, result in report["systems"].items():
        assert set(METRIC_KEYS) <= set(result), name


def test_generated_systems_are_measured_on_unseen_speech(quick_report):
    _, report = quick_report
    unseen = report["systems"]["ddim_k4"]["unseen_speech"]
    assert unseen["seconds"] > 2.0
    assert unseen["jerk"] > 0.0 and unseen["liveliness"]["speed_ratio"] > 0.0
    assert unseen["fgd"] is not None and unseen["fgd"] >= 0.0


def test_live_path_equals_offline_path(quick_report):
    _, report = quick_report
    live = report["deltas"]["live_vs_offline"]
    assert live["frames"]["live"] == live["frames"]["offline"] > 0
    assert live["max_abs_position_difference_m"] == 0.0


def test_report_records_commit_versions_and_plots(quick_report):
    path, report = quick_report
    assert report["commit"] is not None and len(report["commit"]) == 40
    assert report["eval_networks"]["fgd_encoder_version"] >= 1
    assert set(report["deltas"]["ddim_minus_ddpm"]) == {"ddim_k1", "ddim_k2", "ddim_k4", "ddim_k8"}
    assert (path.parent / "results_vs_k.png").is_file()


def test_ground_truth_style_accuracy_uses_the_clip_labels(quick_report):
    _, report = quick_report
    assert set(report["systems"]["ground_truth"]["style_accuracy"]["per_style"]) == {"neutral", "old"}


def test_another_generation_seed_generates_other_motion(quick_report, tiny_model, shared_data, tmp_path):
    _, seed0 = quick_report
    out = tmp_path / "seed1.json"
    bundle = tiny_model[1]
    unseen = shared_data / "speech" / "tts_01_en-us.wav"
    assert main(["eval", "--json", str(out), "--model", str(bundle), "--quick", "--cache",
                 str(bundle.parent / "dataset"), "--unseen", str(unseen), "--systems", "ddim_k4", "--seed", "1"]) == 0
    seed1 = json.loads(out.read_text())
    assert seed0["config"]["seed"] == 0 and seed1["config"]["seed"] == 1
    assert seed1["systems"]["ddim_k4"]["jerk"] != seed0["systems"]["ddim_k4"]["jerk"]
