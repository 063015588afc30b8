"""One stream's poses: the session that turns audio into pose frames, its live controls, and the stages around
the generator (feature buffer, seed motion, smoothing, idle motion, cross-fades, procedural hands).
"""
