import json

import pytest

from gesturecast.errors import UserError
from gesturecast.models.generator.styles import STYLES, canonical_style, style_index

BANDAI_1 = [
    "normal", "happy", "sad", "angry", "proud", "not-confident", "masculinity", "feminine",
    "childish", "old", "tired", "active", "musical", "giant", "chimpira",
]
BANDAI_2 = ["active", "elderly", "exhausted", "feminine", "masculine", "normal", "youthful"]


@pytest.mark.parametrize(
    ("label", "expected"),
    [
        ("elderly", "old"),
        ("Old", "old"),
        ("exhausted", "tired"),
        ("masculinity", "masculine"),
        ("normal", "neutral"),
        ("Neutral", "neutral"),
        ("conversation", "neutral"),
        ("youthful", "childish"),
        ("dataset-2_elderly", "old"),
        ("dataset-1_not-confident", "not-confident"),
        ("not confident", "not-confident"),
        ("Not_Confident", "not-confident"),
        ("Speech", "speech"),
    ],
)
def test_synonyms_merge(label, expected):
    assert canonical_style(label) == expected


def test_bandai_datasets_share_their_seven_styles():
    assert {canonical_style(s) for s in BANDAI_2} <= {canonical_style(s) for s in BANDAI_1}


def test_every_dataset_label_is_known_and_distinct_ones_stay_distinct(shared_data):
    zeggs = json.loads((shared_data / "zeggs" / "data_definition.json").read_text())["label_names"]
    names = {canonical_style(s) for s in [*zeggs, *BANDAI_1, *BANDAI_2]}
    assert names == set(STYLES)
    assert canonical_style("threatening") != canonical_style("chimpira")
    assert canonical_style("still") != canonical_style("neutral")


def test_unknown_style_lists_known_ones():
    with pytest.raises(UserError, match="unknown style 'grumpy'.*neutral"):
        canonical_style("grumpy")


def test_style_index_is_stable_position():
    assert STYLES[style_index("elderly")] == "old"
    assert list(STYLES) == sorted(STYLES)
