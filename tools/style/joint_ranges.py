"""Measure the human joint ranges the stylizer keeps to (``gesturecast.models.style.joint_limits``) from the Bandai
dataset-1 takes and write them: ``python -m gesturecast.tools.style.joint_ranges [--takes ARCHIVE] [--out FILE]``
(numpy only, about ten seconds)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from gesturecast.models.style.joint_limits import DEFAULT_JOINT_RANGES, JointRanges
from gesturecast.models.style.params import STYLED_JOINTS, rotation_vectors
from gesturecast.tools.style.style_fit_command import DEFAULT_RAW, DEFAULT_TAKES, LICENSE_NOTE
from gesturecast.tools.style.takes import Take, load_paired_takes, take_folder

SHARED_CHEST = {"UpperChest": "Chest"}  # Bandai's one chest joint gives both canonical chest joints their range
# the hands' axes differ between the generator's takes (ZeroEGGS: a rest orientation of their own, 150° at the 99th
# percentile) and Bandai's, so a box of Bandai's axes would bend the generator's ordinary hands: only the angle holds
ANGLE_ONLY = ("LeftHand", "RightHand")


def measured_ranges(takes: list[Take]) -> JointRanges:
    """The ranges of every take's styled joints, each joint of :data:`SHARED_CHEST` with its partner's, the joints of
    :data:`ANGLE_ONLY` with no bound on the axes (±π)."""
    vectors = np.concatenate([rotation_vectors(take.motion.rotations) for take in takes])  # (T, S, 3)
    for joint, partner in SHARED_CHEST.items():
        vectors[:, STYLED_JOINTS.index(joint)] = vectors[:, STYLED_JOINTS.index(partner)]
    ranges = JointRanges.measured(vectors)
    unboxed = [STYLED_JOINTS.index(joint) for joint in ANGLE_ONLY]
    ranges.low[unboxed], ranges.high[unboxed] = -np.pi, np.pi
    return ranges


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--takes", type=Path, default=DEFAULT_TAKES, help="Bandai dataset-1 archive or folder")
    parser.add_argument("--raw-cache", type=Path, default=DEFAULT_RAW, help="where the archive is unpacked")
    parser.add_argument("--out", type=Path, default=DEFAULT_JOINT_RANGES, help="the joint-range file to write")
    args = parser.parse_args(argv)
    takes = load_paired_takes(take_folder(args.takes, args.raw_cache))
    measured_ranges(takes).save(args.out, {"license": LICENSE_NOTE, "measured_from": "Bandai Namco Research Motion "
                                           "Dataset, dataset-1", "takes": len(takes)})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
