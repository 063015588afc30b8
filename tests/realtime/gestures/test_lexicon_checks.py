"""A gesture lexicon's files are checked before anything is built from them: bad built-lexicon fields, a clips
archive whose header asks for gigabytes, clip paths out of the folder, clips too big or too short, huge integers
and deep nesting are each one line naming the file."""

import io
import json
import zipfile
from pathlib import Path

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.motion.joint_maps import load_joint_map
from gesturecast.models.motion.motion_features import features_to_motion
from gesturecast.models.motion.retarget import motion_to_bvh
from gesturecast.realtime.gestures import lexicon as gl
from gesturecast.realtime.gestures.lexicon_checks import MAX_CLIP_FILE_BYTES
from gesturecast.tools.gestures.build import save_lexicon


@pytest.fixture(scope="module")
def shipped() -> gl.Lexicon:
    return gl.load_lexicon()


@pytest.fixture
def built(shipped, tmp_path) -> Path:
    save_lexicon(shipped, tmp_path)
    return tmp_path


def edit_built(folder: Path, change) -> None:
    raw = json.loads((folder / gl.LEXICON_FILE).read_text())
    change(raw)
    (folder / gl.LEXICON_FILE).write_text(json.dumps(raw))


@pytest.mark.parametrize(("change", "error"), [
    (lambda raw: raw.update(fps="abc"), "'fps' must be a number"),
    (lambda raw: raw.update(fps=0), "'fps' must be a number"),
    (lambda raw: raw.update(fps=float("nan")), "'fps' must be a number"),
    (lambda raw: raw["gestures"][0].update(triggers=[5]), "'triggers' must be a list of strings"),
    (lambda raw: raw["gestures"][0].update(variants=[]), "'variants' must be a non-empty list"),
    (lambda raw: raw["gestures"][0]["variants"][0].update(stroke_frame="x"), "whole 'stroke_frame'"),
    (lambda raw: raw.update(clips="../clips.npz"), "is not a file in"),
    (lambda raw: raw["gestures"][0]["variants"][1].update(take=-1), "whole 'take'"),
    (lambda raw: raw.update(format_version=1), "format_version 1 is not 2; rebuild it with `gesturecast gestures"),
])
def test_bad_built_lexicon_fields_are_one_line(built, change, error):
    edit_built(built, change)
    with pytest.raises(UserError, match=error):
        gl.load_lexicon(built)


def test_a_clips_archive_asking_for_gigabytes_is_refused_before_any_is_allocated(built):
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f2", "fortran_order": False,
                                                  "shape": (10**9, 136)})  # 272 GB claimed
    key = json.loads((built / gl.LEXICON_FILE).read_text())["gestures"][0]["variants"][0]["clip"]
    with zipfile.ZipFile(built / gl.CLIPS_FILE, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr(f"{key}.npy", header.getvalue() + bytes(1 << 20))  # a MiB of zeros, compressed to 1 KB
    with pytest.raises(UserError, match="more than a gesture lexicon holds"):
        gl.load_lexicon(built)


@pytest.fixture
def user_folder(shipped, tmp_path) -> Path:
    folder = tmp_path / "mine"
    folder.mkdir()
    motion_to_bvh(features_to_motion(shipped["wave"].variant().features.astype(np.float64)), tmp_path / "out.bvh")
    return folder


def write_mapping(folder: Path, clip: str) -> None:
    (folder / gl.USER_MAPPING_FILE).write_text(json.dumps({"x": {"clip": clip, "triggers": ["a"]}}))


def test_a_user_clip_outside_the_folder_is_refused(user_folder):
    (user_folder / "link.bvh").symlink_to(user_folder.parent / "out.bvh")
    for clip in ("../out.bvh", str(user_folder.parent / "out.bvh"), "link.bvh"):
        write_mapping(user_folder, clip)
        with pytest.raises(UserError, match="is not inside"):
            gl.load_lexicon(user_folder)


def test_a_user_clip_too_big_or_too_short_is_one_line_naming_it(shipped, user_folder):
    with open(user_folder / "huge.bvh", "wb") as handle:
        handle.truncate(MAX_CLIP_FILE_BYTES + 1)  # sparse: nothing is written
    write_mapping(user_folder, "huge.bvh")
    with pytest.raises(UserError, match="'clip' huge.bvh is .* a gesture clip is at most 16 MiB"):
        gl.load_lexicon(user_folder)
    features = shipped["wave"].variant().features.astype(np.float64)[:2]  # two frames
    motion_to_bvh(features_to_motion(features), user_folder / "short.bvh")
    write_mapping(user_folder, "short.bvh")
    with pytest.raises(UserError, match="'clip' short.bvh holds 2 frames"):
        gl.load_lexicon(user_folder)


@pytest.mark.parametrize(("text", "error"), [
    ('{"x": {"clip": "short.bvh", "triggers": ["a"], "stroke": 1%s}}' % ("0" * 400), "'stroke'"),
    ('{"x": {"clip": "short.bvh", "triggers": ["a"], "stroke": 1%s}}' % ("0" * 5000), "'stroke'"),
    ("[" * 100_000 + "]" * 100_000, "nested too deep"),
])
def test_huge_integers_and_deep_nesting_in_a_mapping_are_one_line(shipped, user_folder, text, error):
    features = shipped["wave"].variant().features.astype(np.float64)
    motion_to_bvh(features_to_motion(features), user_folder / "short.bvh")
    (user_folder / gl.USER_MAPPING_FILE).write_text(text)
    with pytest.raises(UserError, match=error):
        gl.load_lexicon(user_folder)


@pytest.mark.parametrize("text", ["[" * 100_000 + "]" * 100_000, '{"Hips": %s}' % ("9" * 5000)])
def test_a_joint_map_nested_too_deep_or_with_a_huge_integer_is_one_line(tmp_path, text):
    path = tmp_path / "map.json"
    path.write_text(text)
    with pytest.raises(UserError, match="is not valid JSON"):
        load_joint_map(path)
