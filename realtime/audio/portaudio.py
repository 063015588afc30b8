"""PortAudio (sounddevice) access with user-facing errors: import, device listing, selection, rates.

``import sounddevice`` raises OSError when the PortAudio shared library is missing; a machine
without a microphone has no input devices; a device may refuse a sample rate. Each of these
becomes one :class:`UserError` line saying what to install or which flag to use.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import ModuleType

from gesturecast.errors import UserError

INSTALL_HINT = "install the Debian package libportaudio2 (apt-get install libportaudio2), or use --input FILE"
NO_DEVICE_HINT = "no audio input device found (no microphone?); use --input FILE to read a recording instead"


@dataclass(frozen=True)
class InputDevice:
    index: int
    name: str
    channels: int
    default_rate: float
    host_api: str


def import_sounddevice() -> ModuleType:
    """The sounddevice module, or a UserError naming the missing system library."""
    try:
        import sounddevice
    except OSError as error:
        raise translate_import_error(error) from error
    return sounddevice


def translate_import_error(error: OSError) -> UserError:
    return UserError(f"cannot use the microphone: PortAudio library not loadable ({error}); {INSTALL_HINT}")


def list_input_devices() -> list[InputDevice]:
    sd = import_sounddevice()
    host_apis = sd.query_hostapis()
    return [
        InputDevice(
            index=int(info["index"]),
            name=str(info["name"]),
            channels=int(info["max_input_channels"]),
            default_rate=float(info["default_samplerate"]),
            host_api=str(host_apis[info["hostapi"]]["name"]),
        )
        for info in sd.query_devices()
        if info["max_input_channels"] > 0
    ]


def resolve_input_device(spec: str | None, devices: list[InputDevice]) -> InputDevice:
    """``--device`` value (index, name substring, or None for the first/default) → one device."""
    if not devices:
        raise UserError(NO_DEVICE_HINT)
    if spec is None:
        return devices[0]
    if spec.strip().isdigit():
        by_index = [device for device in devices if device.index == int(spec)]
        if not by_index:
            raise UserError(f"no input device with index {spec}; run `gesturecast devices` to list them")
        return by_index[0]
    matches = [device for device in devices if spec.lower() in device.name.lower()]
    if len(matches) != 1:
        found = ", ".join(f"{d.index}: {d.name}" for d in matches) or "none"
        raise UserError(f"--device {spec!r} must match exactly one input device (matches: {found})")
    return matches[0]


def translate_stream_error(error: Exception, device: InputDevice, sample_rate: int) -> UserError:
    """A sounddevice.PortAudioError from opening/checking a stream → one actionable line."""
    text = str(error)
    if "sample rate" in text.lower():
        return UserError(
            f"device {device.index} ({device.name}) refuses {sample_rate} Hz ({text}); "
            f"try --sample-rate {int(device.default_rate)}"
        )
    return UserError(f"cannot open input device {device.index} ({device.name}) at {sample_rate} Hz: {text}")


def check_input_rate(device: InputDevice, sample_rate: int) -> None:
    sd = import_sounddevice()
    try:
        sd.check_input_settings(device=device.index, channels=1, dtype="float32", samplerate=sample_rate)
    except sd.PortAudioError as error:
        raise translate_stream_error(error, device, sample_rate) from error
