"""PortAudio (sounddevice) access with user-facing errors: import, device listing, selection, rates.

``import sounddevice`` raises OSError when the PortAudio shared library is missing; a machine
without a microphone has no input devices; a device may refuse a sample rate. Each of these
becomes one :class:`UserError` line saying what to install or which flag to use.
"""

from __future__ import annotations

import atexit
import logging
import threading
from dataclasses import dataclass
from types import ModuleType

from gesturecast.errors import UserError

logger = logging.getLogger(__name__)

INSTALL_HINT = "install the Debian package libportaudio2 (apt-get install libportaudio2), or use --input FILE"
NO_DEVICE_HINT = "no audio input device found (no microphone?); use --input FILE to read a recording instead"
CLOSE_BOUND_S = 1.0  # longest wait for PortAudio to close a stream (a stalled device can block it for good)


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


def device_label(device: InputDevice) -> str:
    """How messages name a device: ``input device 3 (USB Audio Device: Mic)``."""
    return f"input device {device.index} ({device.name})"


def capture_time(now: float, adc_time: float, current_time: float, frames: int, sample_rate: int) -> float:
    """Capture time, on the caller's clock, of the first sample of a callback's input block.

    PortAudio gives the block's ADC time and the callback's current time on its own stream clock
    (``time_info.inputBufferAdcTime`` / ``.currentTime``); their difference is how long ago the block
    was captured, whatever the host's buffering. A host API without ADC times reports 0 (or a time
    after ``current_time``): then the block is taken to have ended at ``now``.
    """
    age_s = current_time - adc_time
    if adc_time > 0 and age_s >= 0:
        return now - age_s
    return now - frames / sample_rate


def advancing_adc_time(adc_time: float, previous_adc_time: float) -> float:
    """A block's ADC time, or 0 (untimed) when it does not advance past the previous block's: an ALSA plugin that
    repeats one ADC time would otherwise date every later block back to that moment, and latency would seem to grow
    by a second every second."""
    return adc_time if adc_time > previous_adc_time else 0.0


def close_stream(stream: object, bound_s: float = CLOSE_BOUND_S) -> bool:
    """Abort and close a sounddevice stream off the calling thread, waiting at most ``bound_s``.

    ``stop()`` is never called: it waits for buffers that a stalled device never delivers (it hung
    for good with a silent PulseAudio source). ``abort()`` returns at once on every host seen so far;
    should it block anyway, the caller goes on after ``bound_s`` and sounddevice's exit handler
    (``Pa_Terminate``, which would block the same way) is unregistered. Returns whether it closed.
    """
    closer = threading.Thread(target=_abort_and_close, args=(stream,), name="portaudio-close", daemon=True)
    closer.start()
    closer.join(bound_s)
    if not closer.is_alive():
        return True
    logger.warning("the audio device did not close within %.1f s; leaving it to the operating system", bound_s)
    exit_handler = getattr(import_sounddevice(), "_exit_handler", None)
    if exit_handler is not None:
        atexit.unregister(exit_handler)
    return False


def _abort_and_close(stream: object) -> None:
    stream.abort()
    stream.close()
