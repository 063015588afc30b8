"""One place that builds onnxruntime sessions for real-time use (numpy + onnxruntime only, no torch).

Real-time settings: a fixed, small number of intra-op threads (configurable), one inter-op thread,
sequential execution, and no spin-waiting between runs (spinning would burn the cores that audio
capture and the bridges need while the engine waits for the next latent frame).
"""

from __future__ import annotations

from pathlib import Path

import onnxruntime as ort
from onnxruntime.capi.onnxruntime_pybind11_state import Fail, InvalidArgument, InvalidGraph, InvalidProtobuf

from gesturecast.errors import UserError

DEFAULT_THREADS = 1
NO_SPINNING = "0"
ORT_LOAD_ERRORS = (Fail, InvalidArgument, InvalidGraph, InvalidProtobuf)  # what a bad model file raises


def make_session_options(threads: int = DEFAULT_THREADS) -> ort.SessionOptions:
    """Session options for low-latency single-stream inference on a CPU."""
    if threads < 1:
        raise ValueError(f"threads must be at least 1, got {threads}")
    options = ort.SessionOptions()
    options.intra_op_num_threads = threads
    options.inter_op_num_threads = 1
    options.execution_mode = ort.ExecutionMode.ORT_SEQUENTIAL
    options.graph_optimization_level = ort.GraphOptimizationLevel.ORT_ENABLE_ALL
    options.add_session_config_entry("session.intra_op.allow_spinning", NO_SPINNING)
    options.add_session_config_entry("session.inter_op.allow_spinning", NO_SPINNING)
    return options


def make_session(path_or_bytes: str | Path | bytes, threads: int = DEFAULT_THREADS) -> ort.InferenceSession:
    """A CPU InferenceSession for an ONNX file path or serialized model bytes.

    A file that onnxruntime cannot load (truncated, not ONNX) raises UserError naming it.
    """
    model = path_or_bytes if isinstance(path_or_bytes, bytes) else str(path_or_bytes)
    options = make_session_options(threads)
    try:
        return ort.InferenceSession(model, sess_options=options, providers=["CPUExecutionProvider"])
    except ORT_LOAD_ERRORS as error:
        source = "the ONNX model bytes" if isinstance(path_or_bytes, bytes) else str(path_or_bytes)
        first_line = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise UserError(f"cannot load {source}: not a valid ONNX model ({first_line}); re-export the bundle") from None
