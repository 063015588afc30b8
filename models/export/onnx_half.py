"""Store an ONNX model's large float32 weights as float16 (half the file size), computing in float32.

Each large float32 initializer ``w`` becomes a float16 initializer plus a ``Cast(to=float)`` node
producing ``w`` again. onnxruntime constant-folds those casts when it loads the session, so the
graph runs exactly as the float32 graph of the *rounded* weights, at no run-time cost. Callers round
the torch weights with :func:`round_weights_to_half` before export so torch and onnxruntime keep
agreeing (the rounding then loses nothing in the conversion).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
import torch
from onnx import TensorProto, helper, numpy_helper

MIN_ELEMENTS = 256  # smaller tensors (norm constants, shapes) stay float32: nothing to gain
HALF_SUFFIX = "__float16"


def round_weights_to_half(module: torch.nn.Module) -> torch.nn.Module:
    """Round every floating parameter and buffer to the nearest float16 value (kept as float32), in place."""
    with torch.no_grad():
        for tensor in [*module.parameters(), *module.buffers()]:
            if tensor.is_floating_point():
                tensor.copy_(tensor.half().float())
    return module


def _halve(initializer: TensorProto) -> tuple[TensorProto, onnx.NodeProto]:
    values = numpy_helper.to_array(initializer)
    half = numpy_helper.from_array(values.astype(np.float16), initializer.name + HALF_SUFFIX)
    cast = helper.make_node("Cast", [half.name], [initializer.name], to=TensorProto.FLOAT,
                            name=initializer.name + "_cast")
    return half, cast


def store_weights_in_half(path: Path | str) -> Path:
    """Rewrite the ONNX file at ``path`` with its large float32 initializers stored as float16."""
    path = Path(path)
    model = onnx.load(str(path))
    graph = model.graph
    large = [init for init in graph.initializer
             if init.data_type == TensorProto.FLOAT and int(np.prod(init.dims)) >= MIN_ELEMENTS]
    converted = [_halve(init) for init in large]
    for init in large:
        graph.initializer.remove(init)
    graph.initializer.extend(half for half, _ in converted)
    casts = [cast for _, cast in converted]
    nodes = casts + list(graph.node)  # casts first: the graph stays topologically sorted
    del graph.node[:]
    graph.node.extend(nodes)
    onnx.checker.check_model(model)
    onnx.save(model, str(path))
    return path
