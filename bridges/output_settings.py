"""Where the poses go: :class:`Outputs`, the typed form of ``live``'s output flags (checked when made).

``Outputs(vmc="127.0.0.1")`` streams VMC to port 39539 (39540 for ``vmc_role="assistant"``), ``osc=HOST:PORT``
plain OSC, ``ws=PORT`` the WebSocket stream and browser viewer, ``bvh=PATH`` records a BVH file.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from gesturecast.arguments import MAX_PORT
from gesturecast.bridges.coords import FRAMES
from gesturecast.bridges.vmc_roles import ASSISTANT, DEFAULT_PORTS, MARIONETTE
from gesturecast.errors import UserError

LOOPBACK = "127.0.0.1"
VMC_ROLES = (MARIONETTE, ASSISTANT)


def parse_host_port(value: str, name: str) -> tuple[str, int]:
    """``HOST:PORT`` → (host, port); an empty host is loopback; an IPv6 host may be bracketed (``[::1]:39539``,
    or ``::1:39539``); a one-line error naming ``name`` otherwise."""
    host, separator, port = str(value).rpartition(":")
    if not separator or not port.isdigit() or not 0 < int(port) <= MAX_PORT:
        raise UserError(f"{name} wants HOST:PORT (e.g. 127.0.0.1:39539), got {value!r}")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    return host or LOOPBACK, int(port)


@dataclass(frozen=True)
class Outputs:
    """The outputs of a stream (none by default: frames go only to the caller).

    vmc: ``HOST[:PORT]`` of a VMC receiver (VSeeFace, Warudo, EVMC4U, VMC4UE); vmc_role: "marionette" (the
        receiver shows our whole avatar) or "assistant" (a Performer mixes our bones with its tracking);
        vmc_bones: "all", "upper", "arms", "none" or a comma list (default: all; assistant: upper).
    osc: ``HOST:PORT`` for plain OSC; osc_frame: "unity", "unreal" or "internal" coordinates.
    ws: WebSocket stream + browser viewer port (0: any free port); host: its listen address; token,
        token_file: the shared secret clients send; allow_origins: other page origins to accept; avatar: the
        viewer's VRM (default: the bundled one).
    bvh: record the stream as a BVH file.
    """

    vmc: str | None = None
    vmc_role: str = MARIONETTE
    vmc_bones: str | None = None
    osc: str | None = None
    osc_frame: str = "unity"
    ws: int | None = None
    host: str = LOOPBACK
    token: str | None = None
    token_file: Path | None = None
    allow_origins: tuple[str, ...] = ()
    avatar: Path | None = None
    bvh: Path | None = None

    def __post_init__(self) -> None:
        if self.vmc_role not in VMC_ROLES:
            raise UserError(f"vmc_role must be one of {', '.join(VMC_ROLES)}, got {self.vmc_role!r}")
        if self.osc_frame not in FRAMES:
            raise UserError(f"osc_frame must be one of {', '.join(FRAMES)}, got {self.osc_frame!r}")
        if self.ws is not None and (isinstance(self.ws, bool) or not isinstance(self.ws, int)
                                    or not 0 <= self.ws <= MAX_PORT):
            raise UserError(f"ws must be a port from 0 to {MAX_PORT}, got {self.ws!r}")
        if self.avatar is not None and self.ws is None:
            raise UserError("avatar sets the viewer's avatar: it goes with a WebSocket port (ws, --ws PORT)")
        if self.vmc is not None:
            self.vmc_address()
        if self.osc is not None:
            parse_host_port(self.osc, "osc")
        object.__setattr__(self, "allow_origins", tuple(self.allow_origins))
        for name in ("token_file", "avatar", "bvh"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, Path(getattr(self, name)))

    @property
    def any(self) -> bool:
        """Whether any output is chosen."""
        return any(value is not None for value in (self.vmc, self.osc, self.ws, self.bvh))

    @property
    def assistant(self) -> bool:
        return self.vmc_role == ASSISTANT

    def vmc_address(self) -> tuple[str, int]:
        """(host, port) of ``vmc``, with the role's customary port when none is given (an IPv6 host in brackets:
        ``[::1]`` or ``[::1]:39539``)."""
        has_port = "]:" in self.vmc if self.vmc.startswith("[") else ":" in self.vmc
        value = self.vmc if has_port else f"{self.vmc}:{DEFAULT_PORTS[self.vmc_role]}"
        return parse_host_port(value, "vmc")

    def vmc_bone_spec(self) -> str:
        """The bone selection: as given, else the upper body for an assistant and everything for a marionette."""
        return self.vmc_bones or ("upper" if self.assistant else "all")
