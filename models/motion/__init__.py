"""Motion representation (numpy): canonical skeleton, rotations, BVH, joint maps, rest-pose alignment,
retargeting, motion features.
"""
