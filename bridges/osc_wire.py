"""Minimal OSC 1.0 encoding for the bridges: fixed-layout messages and size-capped bundles.

Only the argument types receivers accept are produced: ``s`` (string), ``f`` (big-endian
float32) and ``i`` (big-endian int32). A :class:`MessageLayout` pre-encodes everything that
does not change between frames (address, type tags, string arguments), so a frame costs one
``tobytes`` per message. Bundles carry the "immediately" time tag.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence

import numpy as np

OSC_ALIGNMENT = 4
BUNDLE_TAG = b"#bundle\x00"
IMMEDIATE_TIMETAG = struct.pack(">Q", 1)
BUNDLE_HEADER_SIZE = len(BUNDLE_TAG) + len(IMMEDIATE_TIMETAG)  # 16
ELEMENT_SIZE_PREFIX = 4
# UDP payload that crosses a 1500-byte Ethernet MTU unfragmented: 1500 − 20 (IPv4 header) − 8 (UDP header),
# and 1500 − 40 (IPv6 header) − 8 over IPv6 (docs/architecture.md, "VMC protocol essentials")
IPV4_MAX_DATAGRAM_SIZE = 1472
IPV6_MAX_DATAGRAM_SIZE = 1452
MAX_DATAGRAM_SIZE = IPV4_MAX_DATAGRAM_SIZE  # an encoder's default when it does not know the destination
NUMERIC_TAGS = frozenset("fi")


def osc_string(text: str) -> bytes:
    """ASCII, NUL-terminated, zero-padded to a multiple of 4 bytes."""
    raw = text.encode("ascii") + b"\x00"
    return raw + b"\x00" * (-len(raw) % OSC_ALIGNMENT)


class MessageLayout:
    """An OSC message whose address and string arguments are fixed and whose numbers vary.

    ``numbers`` is the type-tag string of the numeric arguments, e.g. ``"fffffff"`` or ``"i"``;
    the string arguments come first.
    """

    def __init__(self, address: str, strings: Sequence[str] = (), numbers: str = "") -> None:
        if not set(numbers) <= NUMERIC_TAGS:
            raise ValueError(f"numeric type tags must be 'f' or 'i', got {numbers!r}")
        tags = "," + "s" * len(strings) + numbers
        self.address = address
        self.numbers = numbers
        self.prefix = osc_string(address) + osc_string(tags) + b"".join(osc_string(s) for s in strings)
        self._struct = struct.Struct(">" + numbers)

    @property
    def size(self) -> int:
        return len(self.prefix) + self._struct.size

    def encode(self, *values: float) -> bytes:
        """One message; ``values`` match ``numbers`` (ints for ``i``, anything float-like for ``f``)."""
        return self.prefix + self._struct.pack(*values)

    def encode_floats(self, values: np.ndarray) -> bytes:
        """One all-float message from a (len(numbers),) array."""
        return self.prefix + np.asarray(values, dtype=">f4").tobytes()


def encode_float_rows(layouts: Sequence[MessageLayout], rows: np.ndarray) -> list[bytes]:
    """Messages for all-float layouts, row i of (N, K) ``rows`` → layouts[i]; one dtype cast in total."""
    big_endian = np.ascontiguousarray(rows, dtype=">f4")  # (N, K)
    return [layout.prefix + row.tobytes() for layout, row in zip(layouts, big_endian, strict=True)]


def encode_weight_groups(groups: Sequence[tuple[Sequence[MessageLayout], np.ndarray | None]]) -> list[bytes]:
    """One float message per name of each (layouts, weights (n,)) group; a group without layouts or weights (lip sync
    or the face off, a frame that carries none) sends nothing."""
    messages = []
    for layouts, weights in groups:
        if layouts and weights is not None:
            messages += encode_float_rows(layouts, np.asarray(weights)[:, None])  # (n, 1)
    return messages


def bundle(messages: Sequence[bytes]) -> bytes:
    """An OSC bundle (time tag "immediately") holding ``messages`` in order."""
    parts = [BUNDLE_TAG, IMMEDIATE_TIMETAG]
    for message in messages:
        parts.append(struct.pack(">i", len(message)))
        parts.append(message)
    return b"".join(parts)


def pack_bundles(messages: Sequence[bytes], max_size: int = MAX_DATAGRAM_SIZE) -> list[bytes]:
    """Greedily group messages, in order, into bundles of at most ``max_size`` bytes each."""
    groups: list[list[bytes]] = []
    size = max_size  # forces a new group on the first message
    for message in messages:
        needed = ELEMENT_SIZE_PREFIX + len(message)
        if BUNDLE_HEADER_SIZE + needed > max_size:
            raise ValueError(f"an OSC message of {len(message)} bytes cannot fit a {max_size}-byte bundle")
        if size + needed > max_size:
            groups.append([])
            size = BUNDLE_HEADER_SIZE
        groups[-1].append(message)
        size += needed
    return [bundle(group) for group in groups]
