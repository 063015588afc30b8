"""Fitting the stylizer and the style judge from content-paired Bandai takes (a few real actions and styles)."""

from __future__ import annotations

import json
import tarfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gesturecast.cli import main
from gesturecast.models.motion.rotations import quat_from_axis_angle
from gesturecast.models.style.descriptors import window_features
from gesturecast.models.style.judge import LOGGED, StyleJudge, centred, logged_features
from gesturecast.models.style.params import (
    LOG_GAIN,
    OFFSET,
    STYLED_INDEX,
    STYLED_JOINTS,
    TENSION,
    StyleBook,
    StyleFilter,
    StyleParams,
    rotation_vectors,
)
from gesturecast.tools.style.calibrate import calibrate, scaled
from gesturecast.tools.style.fit import REST, fit_styles
from gesturecast.tools.style.held_out import held_out_actions
from gesturecast.tools.style.judge_fit import fit_judge
from gesturecast.tools.style.takes import Take, load_paired_takes

CONTENTS = ("bye", "byebye", "guide", "bow")
STYLES = ("normal", "sad", "old", "happy")


@pytest.fixture(scope="module")
def takes_folder(tmp_path_factory, shared_data) -> Path:
    """The dataset-1 takes of CONTENTS × STYLES, extracted from the archive."""
    folder = tmp_path_factory.mktemp("bandai")
    with tarfile.open(shared_data / "bandai" / "dataset-1.tar.xz", "r:xz") as tar:
        members = [m for m in tar.getmembers() if any(f"_{c}_{s}_" in Path(m.name).name
                                                      for c in CONTENTS for s in STYLES)]
        tar.extractall(folder, members=members, filter="data")
    return folder


@pytest.fixture(scope="module")
def takes(takes_folder) -> list[Take]:
    return load_paired_takes(takes_folder)


def restyled(take: Take, values: np.ndarray) -> Take:
    """The take re-performed by the stylizer's filter with parameters ``values`` (S, CHANNELS), as style "sad"."""
    v = rotation_vectors(take.motion.rotations)  # (T, S, 3)
    styled = StyleFilter(take.motion.fps, REST).run(v, np.broadcast_to(values, (len(v), *values.shape)),
                                                     np.arange(len(v)) / take.motion.fps)
    rotations = take.motion.rotations.copy()
    rotations[:, STYLED_INDEX] = quat_from_axis_angle(styled)
    return replace(take, style="sad", motion=replace(take.motion, rotations=rotations))


def test_the_fit_recovers_a_style_made_with_known_parameters(takes):
    known = StyleParams.identity().values.copy()
    head = STYLED_JOINTS.index("Head")
    arms = [STYLED_JOINTS.index(name) for name in STYLED_JOINTS if "Arm" in name or "Hand" in name]
    known[head, OFFSET] = (0.3, 0.0, 0.0)  # the head bowed
    known[arms, LOG_GAIN] = np.log(0.6)  # smaller arm gestures
    known[arms, TENSION] = -0.6  # slower, smoother
    neutral = [take for take in takes if take.style == "neutral"]
    styles, report = fit_styles(neutral + [restyled(take, known) for take in neutral])
    fitted = styles["sad"].values
    np.testing.assert_allclose(fitted[head, OFFSET], known[head, OFFSET], atol=0.05)
    assert np.exp(fitted[arms, LOG_GAIN]) == pytest.approx(0.6, abs=0.12)
    assert (fitted[arms, TENSION] < -0.3).all()
    assert report["sad"]["arms"]["tempo_ratio"] < 0.9 and report["sad"]["arms"]["contents"] == len(CONTENTS)
    assert not styles["neutral"].values.any()


def test_the_judge_is_measured_on_actions_it_never_saw(takes):
    judge, report = fit_judge(takes, ("neutral", "sad", "old", "happy"))
    assert report["contents"] == len(CONTENTS)
    assert sum(report["windows_per_style"]) == np.sum(report["confusion"])
    assert report["mean"] > report["chance"] + 0.15
    assert judge.labels == ("neutral", "sad", "old", "happy")


def test_style_fit_writes_the_styles_and_the_judge_it_reports(takes_folder, tmp_path, capsys):
    assert main(["style-fit", "--takes", str(takes_folder), "--out", str(tmp_path), "--contents", "bye", "guide"]) == 0
    printed = json.loads(capsys.readouterr().out)
    book = StyleBook.load(tmp_path / "styles.json")
    assert set(book.labels) == {"neutral", "sad", "old", "happy"} and "non-commercial" in book.meta["license"]
    assert printed["styles"]["sad"]["arms"]["contents"] == 2
    judge = StyleJudge.load(tmp_path / "judge.json")
    assert judge.weights.shape == (len(judge.mean), len(judge.labels))


def test_the_learned_and_the_fitted_stylizer_are_measured_on_actions_neither_saw(takes):
    pytest.importorskip("torch")
    from gesturecast.tools.style.compare import compare_stylizers

    report = compare_stylizers(takes, seeds=(0,), steps=20)
    assert report["cases"] == len(CONTENTS) * (len(STYLES) - 1)
    assert set(report["held_out_fk_distance"]) == {"unchanged", "fitted", "learned_seed0"}
    assert all(np.isfinite(value) and value > 0.0 for value in report["held_out_fk_distance"].values())


def test_the_calibration_restores_a_posture_the_fit_made_too_small(takes):
    known = StyleParams.identity().values.copy()
    known[STYLED_JOINTS.index("Chest"), OFFSET] = (0.25, 0.0, 0.0)  # bent forward
    known[STYLED_JOINTS.index("Head"), OFFSET] = (0.3, 0.0, 0.0)
    neutral = [take for take in takes if take.style == "neutral"]
    pairs = neutral + [restyled(take, known) for take in neutral]
    halved = StyleParams(scaled(known, 0.5))
    styles, chosen = calibrate({"neutral": StyleParams.identity(), "sad": halved}, pairs)
    assert chosen["sad"]["offset_scale"] == 2.0 and chosen["sad"]["error"] < chosen["sad"]["error_unscaled"]
    np.testing.assert_allclose(styles["sad"].values, known, atol=1e-9)
    assert "neutral" not in chosen and styles["neutral"].is_identity


def test_the_stylizer_is_judged_on_actions_neither_it_nor_the_judge_saw(takes):
    report = held_out_actions(takes, ("neutral", "sad", "old", "happy"))
    assert report["actions"] == sorted(CONTENTS)
    for variant in ("median", "calibrated"):
        assert 0.0 <= report[variant]["judge"]["mean"] <= 1.0
        assert set(report[variant]["judge"]["per_style"]) == {"neutral", "sad", "old", "happy"}
        assert np.isfinite(report[variant]["fk_distance_to_real"]) and report[variant]["fk_distance_to_real"] > 0.0
    assert "skipped" in held_out_actions(takes, ("neutral", "sad", "old", "happy", "angry"))


def test_the_judge_reads_a_set_the_same_whatever_the_size_of_its_style_differences(takes):
    features = [window_features(take.motion.rotations, take.motion.root_position, take.motion.fps)
                for take in takes if take.content == "bye"]
    logged = [logged_features(f) for f in features]
    reference = np.mean([f.mean(axis=0) for f in logged], axis=0)
    doubled = [f.copy() for f in features]  # every style's difference twice as large
    for f, log_f in zip(doubled, logged, strict=True):
        plain = np.setdiff1d(np.arange(f.shape[1]), LOGGED)
        f[:, plain] = reference[plain] + 2.0 * (log_f[:, plain] - reference[plain])
        f[:, LOGGED] = np.exp(reference[LOGGED] + 2.0 * (log_f[:, LOGGED] - reference[LOGGED]))
    for a, b in zip(centred(features), centred(doubled), strict=True):
        np.testing.assert_allclose(a, b, atol=1e-3)  # up to the spread's 1e-6 guard
    with pytest.raises(ValueError, match="at least 3 clips"):
        centred(features[:2])


def test_the_joint_ranges_are_measured_from_the_takes_and_written(takes_folder, tmp_path):
    from gesturecast.models.style.joint_limits import JointRanges
    from gesturecast.tools.style.joint_ranges import main

    assert main(["--takes", str(takes_folder), "--out", str(tmp_path / "ranges.json")]) == 0
    ranges = JointRanges.load(tmp_path / "ranges.json")
    chest, upper = STYLED_JOINTS.index("Chest"), STYLED_JOINTS.index("UpperChest")
    np.testing.assert_array_equal(ranges.high[upper], ranges.high[chest])  # Bandai's one chest joint gives both
    assert np.all(ranges.low < ranges.high) and np.all(ranges.angle > 0)
