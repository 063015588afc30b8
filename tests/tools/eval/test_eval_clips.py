"""Evaluation reads full-body takes only: an arms-only take (SHOW) has no legs or root to compare with."""

from gesturecast.models.dataset.cache import build_dataset
from gesturecast.models.dataset.sources import show_takes, smplx_takes
from gesturecast.models.evaluation.data import real_clips
from gesturecast.tools.eval.clips import held_out_clips


def test_arms_only_takes_are_left_out_of_evaluation(tmp_path, shared_data):
    show = [t for t in show_takes(shared_data / "show") if t.name.startswith("seth_98201")]
    build_dataset(show + smplx_takes(shared_data / "beat2", dataset="beat2"), tmp_path / "cache", progress=False)
    assert [clip.name.split("/")[0] for clip in held_out_clips(tmp_path / "cache")] == ["beat2"]
    assert {clip.dataset for clip in real_clips(tmp_path / "cache", ("train", "val", "test"))} == {"beat2"}
