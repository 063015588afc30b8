"""BVH reading/writing: round trips, odd layouts, bad input."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gesturecast.errors import UserError
from gesturecast.models.motion.bvh import read_bvh, write_bvh
from gesturecast.models.motion.rotations import quat_from_euler, quat_mul

ODD_BVH = """HIERARCHY
ROOT Root
{
  OFFSET 1 2 3
  CHANNELS 6 Yrotation Xposition Zrotation Yposition Xrotation Zposition
  JOINT Mid
  {
    OFFSET 0 10 0
    CHANNELS 6 Xposition Yposition Zposition Xrotation Yrotation Zrotation
    JOINT Tip
    {
      OFFSET 0 5 0
      CHANNELS 3 Yrotation Zrotation Xrotation
      End Site
      {
        OFFSET 0 2.5 0
      }
    }
  }
}
MOTION
Frames: 2
Frame Time: .0083333
10 1 20 2 30 3 0 10 0 5 6 7 -40 50 60
-10 4 -20 5 -30 6 0 11 0 1 2 3 0 0 0
"""


@pytest.fixture()
def odd_file(tmp_path: Path) -> Path:
    path = tmp_path / "odd.bvh"
    path.write_text(ODD_BVH)
    return path


def test_reads_odd_channel_orders_and_end_sites(odd_file: Path) -> None:
    data = read_bvh(odd_file)
    assert data.names == ["Root", "Mid", "Tip"]
    assert list(data.parents) == [-1, 0, 1]
    assert data.fps == pytest.approx(1 / 0.0083333)
    np.testing.assert_allclose(data.end_sites[2], [0, 2.5, 0])
    translations = data.local_translations()
    np.testing.assert_allclose(translations[0, 0], [1, 2, 3])  # root position channels, interleaved
    np.testing.assert_allclose(translations[1, 1], [0, 11, 0])  # 6-channel joint: channels replace OFFSET
    np.testing.assert_allclose(translations[0, 2], [0, 5, 0])  # 3-channel joint: OFFSET
    rotations = data.local_rotations()
    # root "Yrotation ... Zrotation ... Xrotation": R = Ry(10) Rz(20) Rx(30), intrinsic as in BVH
    ry, rz, rx = (quat_from_euler(np.deg2rad([[a]]), axis)[0] for a, axis in ((10, "Y"), (20, "Z"), (30, "X")))
    np.testing.assert_allclose(rotations[0, 0], quat_mul(quat_mul(ry, rz), rx), atol=1e-12)
    np.testing.assert_allclose(rotations[0, 2], quat_from_euler(np.deg2rad([-40.0, 50, 60]), "YZX"), atol=1e-12)


def test_round_trip_preserves_rotations(odd_file: Path, tmp_path: Path) -> None:
    data = read_bvh(odd_file)
    out = tmp_path / "out.bvh"
    write_bvh(data, out)
    again = read_bvh(out)
    assert again.names == data.names and again.channels == data.channels
    np.testing.assert_allclose(again.frame_time, data.frame_time, rtol=1e-9)
    dots = np.abs(np.sum(again.local_rotations() * data.local_rotations(), axis=-1))
    angle_error_deg = np.degrees(2 * np.arccos(np.clip(dots, -1, 1)))
    assert angle_error_deg.max() < 1e-4
    np.testing.assert_allclose(again.end_sites[2], data.end_sites[2])


def test_crlf_line_endings(odd_file: Path, tmp_path: Path) -> None:
    crlf = tmp_path / "crlf.bvh"
    crlf.write_bytes(ODD_BVH.replace("\n", "\r\n").encode())
    np.testing.assert_array_equal(read_bvh(crlf).motion, read_bvh(odd_file).motion)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (ODD_BVH.replace("Frames: 2", "Frames: 0"), "zero frames"),
        (ODD_BVH.rsplit("\n", 2)[0], "truncated"),
        (ODD_BVH.split("MOTION")[0][:120], "truncated"),
        ("just some notes\nnot motion\n", "not a BVH file"),
        (ODD_BVH.replace("-10 4 -20", "-10 4"), "frame 1 has 14 values"),
        (ODD_BVH.replace("Xrotation Yrotation Zrotation", "Xrotation Yrotation Wrotation"), "unknown BVH channel"),
        (ODD_BVH.replace("OFFSET 0 10 0", "OFFSET 0 nan 0"), "joint 'Mid' OFFSET holds a NaN or infinite"),
        (ODD_BVH.replace("OFFSET 0 2.5 0", "OFFSET 0 -inf 0"), "End Site of joint 'Tip' OFFSET holds a NaN"),
        (ODD_BVH.replace("OFFSET 0 5 0", "OFFSET 0 1e30 0"), "joint 'Tip' OFFSET value 1e\\+30 is beyond"),
        (ODD_BVH.replace("10 1 20 2 30 3", "10 1 20 1e30 30 3"), "frame 0 joint 'Root' Yposition value 1e\\+30"),
    ],
)
def test_bad_input_is_one_line_user_error(tmp_path: Path, text: str, message: str) -> None:
    path = tmp_path / "bad.bvh"
    path.write_text(text)
    with pytest.raises(UserError, match=message) as info:
        read_bvh(path)
    assert "\n" not in str(info.value)


def test_missing_file_is_user_error(tmp_path: Path) -> None:
    with pytest.raises(UserError, match="cannot read"):
        read_bvh(tmp_path / "nope.bvh")


def test_a_folder_or_device_is_refused_before_reading(tmp_path: Path) -> None:
    """A device (``/dev/zero``) has no size to check: only a regular file is read (at most the size limit)."""
    with pytest.raises(UserError, match="not a regular file"):
        read_bvh(tmp_path)


def test_failed_write_leaves_no_file(odd_file: Path, tmp_path: Path) -> None:
    data = read_bvh(odd_file)
    data.motion = np.array([["not", "numbers", *["x"] * 13]], dtype=object)
    out = tmp_path / "half.bvh"
    with pytest.raises(TypeError):
        write_bvh(data, out)
    assert list(tmp_path.iterdir()) == [odd_file]


def test_rotation_channels_beyond_a_turn_are_read_modulo_360(odd_file: Path, tmp_path: Path) -> None:
    """1e308° in a rotation channel gave NaN rotations (and NaN poses from a motion prompt); any finite angle is a
    rotation, read modulo 360°."""
    plain = read_bvh(odd_file)
    turned = tmp_path / "turned.bvh"
    turned.write_text(ODD_BVH.replace("10 1 20 2 30 3", "730 1 -1060 2 30 3"))  # + 2 turns, - 3 turns
    np.testing.assert_allclose(np.abs(read_bvh(turned).local_rotations()), np.abs(plain.local_rotations()),
                               atol=1e-9)
    huge = tmp_path / "huge.bvh"
    huge.write_text(ODD_BVH.replace("10 1 20 2 30 3", "1e308 1 -1e308 2 30 3"))
    assert np.isfinite(read_bvh(huge).local_rotations()).all()


PEAK_MEMORY = ("import re, sys; from pathlib import Path; from gesturecast.models.motion.bvh import read_bvh; "
               "peak = lambda: int(re.search(r'VmHWM:\\s*(\\d+)', Path('/proc/self/status').read_text()).group(1)); "
               "before = peak(); read_bvh(sys.argv[1]); print(peak() - before)")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the peak memory from /proc")
def test_reading_a_large_bvh_takes_a_few_times_its_size_in_memory(odd_file: Path, tmp_path: Path) -> None:
    """A 70 MB motion prompt took about 13 times its size (945 MB): every value was a Python string at once. The
    peak resident memory is a fresh process's (VmHWM: not inherited from this one, unlike ru_maxrss)."""
    data = read_bvh(odd_file)
    data.motion = np.tile(data.motion, (40000, 1))  # (80000, 15): about 11 MB of text
    path = tmp_path / "large.bvh"
    write_bvh(data, path)
    result = subprocess.run([sys.executable, "-c", PEAK_MEMORY, str(path)], capture_output=True, text=True, check=True)
    assert int(result.stdout) * 1024 < 4 * path.stat().st_size
