"""glTF 2.0 binary container (GLB): a JSON chunk and one BIN chunk of float32 accessors.

Layout (glTF 2.0 spec, "GLB File Format Specification"): a 12-byte header (magic ``glTF``, version 2,
total length), then chunks of (uint32 length, uint32 type, data), each padded to 4 bytes: JSON (padded
with spaces), then BIN (padded with zeros). Used by :mod:`gesturecast.bridges.vrma`.
"""

from __future__ import annotations

import json
import struct

import numpy as np

GLB_MAGIC = b"glTF"
GLB_VERSION = 2
CHUNK_JSON = 0x4E4F534A  # "JSON"
CHUNK_BIN = 0x004E4942  # "BIN\0"
GLB_HEADER = struct.Struct("<4sII")
CHUNK_HEADER = struct.Struct("<II")
FLOAT = 5126  # glTF componentType of float32
ACCESSOR_TYPES = {1: "SCALAR", 3: "VEC3", 4: "VEC4"}  # components per element -> glTF accessor type


def _padded(data: bytes, fill: bytes) -> bytes:
    return data + fill * (-len(data) % 4)


class FloatBuffer:
    """The BIN chunk being built: each :meth:`add` appends one tightly packed float32 accessor."""

    def __init__(self) -> None:
        self.accessors: list[dict] = []
        self.buffer_views: list[dict] = []
        self._parts: list[bytes] = []
        self._length = 0

    def add(self, values: np.ndarray, with_bounds: bool = False) -> int:
        """values (count,) or (count, C) with C in 3, 4 -> the accessor index (min / max when asked)."""
        values = np.asarray(values, dtype="<f4")
        data = values.tobytes()
        self.buffer_views.append({"buffer": 0, "byteOffset": self._length, "byteLength": len(data)})
        accessor = {"bufferView": len(self.buffer_views) - 1, "componentType": FLOAT, "count": len(values),
                    "type": ACCESSOR_TYPES[1 if values.ndim == 1 else values.shape[1]]}
        if with_bounds:
            accessor["min"] = np.atleast_1d(values.min(axis=0)).tolist()
            accessor["max"] = np.atleast_1d(values.max(axis=0)).tolist()
        self.accessors.append(accessor)
        self._parts.append(data)  # float32 data keeps every view 4-byte aligned
        self._length += len(data)
        return len(self.accessors) - 1

    def data(self) -> bytes:
        return b"".join(self._parts)


def glb_bytes(document: dict, buffer: FloatBuffer) -> bytes:
    """The GLB file of ``document`` (its accessors, bufferViews and buffers are filled in from ``buffer``)."""
    binary = _padded(buffer.data(), b"\0")
    document = {**document, "accessors": buffer.accessors, "bufferViews": buffer.buffer_views,
                "buffers": [{"byteLength": len(binary)}]}
    text = _padded(json.dumps(document, separators=(",", ":")).encode("utf-8"), b" ")
    chunks = CHUNK_HEADER.pack(len(text), CHUNK_JSON) + text + CHUNK_HEADER.pack(len(binary), CHUNK_BIN) + binary
    return GLB_HEADER.pack(GLB_MAGIC, GLB_VERSION, GLB_HEADER.size + len(chunks)) + chunks


def read_glb(data: bytes) -> tuple[dict, bytes]:
    """(JSON document, BIN chunk) of a GLB file; ValueError when it is not one."""
    magic, version, length = GLB_HEADER.unpack_from(data)
    if magic != GLB_MAGIC or version != GLB_VERSION or length != len(data):
        raise ValueError("not a glTF 2.0 binary file")
    json_length, json_type = CHUNK_HEADER.unpack_from(data, GLB_HEADER.size)
    json_start = GLB_HEADER.size + CHUNK_HEADER.size
    bin_length, bin_type = CHUNK_HEADER.unpack_from(data, json_start + json_length)
    if (json_type, bin_type) != (CHUNK_JSON, CHUNK_BIN):
        raise ValueError("a GLB file wants a JSON chunk, then a BIN chunk")
    bin_start = json_start + json_length + CHUNK_HEADER.size
    return json.loads(data[json_start:json_start + json_length]), data[bin_start:bin_start + bin_length]


def accessor_values(document: dict, binary: bytes, index: int) -> np.ndarray:
    """The float32 values of accessor ``index``: (count,) or (count, C)."""
    accessor = document["accessors"][index]
    view = document["bufferViews"][accessor["bufferView"]]
    width = {v: k for k, v in ACCESSOR_TYPES.items()}[accessor["type"]]
    values = np.frombuffer(binary, dtype="<f4", count=accessor["count"] * width,
                           offset=view.get("byteOffset", 0) + accessor.get("byteOffset", 0))
    return values if width == 1 else values.reshape(-1, width)
