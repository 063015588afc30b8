"""Control messages on the wire: a client's JSON text → a message object, and its control fields → typed controls.

A control message is a JSON object ``{"type": "control", <fields>..., "token": "..."}`` with at least one known
field (:data:`gesturecast.controls.CONTROL_FIELDS`); ``{"type": "words", "words": [...]}`` is the same as a control
holding only words. The fields are checked by :func:`gesturecast.controls.parse_controls`, the one check of every
door, so nothing invalid reaches the engine and every door refuses a bad field in the same words. Both WebSocket
servers (the ``--ws`` output and ``serve``) hand a control message to their session and answer it with
:func:`submit_control`: the same refusals, the same ``ack``.
"""

from __future__ import annotations

import asyncio
import json
from collections.abc import Callable

from gesturecast.controls import Control, ControlError, acknowledged, parse_controls
from gesturecast.errors import UserError
from gesturecast.message_rate import MessageRate

ENVELOPE_FIELDS = frozenset({"type", "token"})
WORDS_MESSAGE = "words"  # {"type": "words", "words": [...]}: the same as a control with only words


def decode_client_message(text: str) -> dict:
    """A client's text message → a JSON object with a string ``type``; ControlError (one line) otherwise.

    Python's parser raises more than JSONDecodeError on hostile input: RecursionError for deeply
    nested arrays, ValueError for integers beyond its digit limit; all of them are one-line refusals.
    """
    try:
        decoded = json.loads(text)
    except RecursionError:
        raise ControlError("not JSON (nested too deeply)") from None
    except json.JSONDecodeError as error:
        raise ControlError(f"not JSON ({error.msg})") from None
    except ValueError:  # an integer beyond sys.get_int_max_str_digits()
        raise ControlError("not JSON (a number has too many digits)") from None
    if not isinstance(decoded, dict) or not isinstance(decoded.get("type"), str):
        raise ControlError('a message must be a JSON object with a "type"')
    return decoded


def message_controls(message: dict) -> tuple[Control, ...]:
    """The typed controls of a decoded ``control`` message (its envelope, type and token, set aside)."""
    return parse_controls(message, ENVELOPE_FIELDS)


async def submit_control(message: dict, submit: Callable[[tuple[Control, ...]], dict | None],
                         rate: MessageRate) -> str:
    """Check a decoded control message and the connection's ``rate``, hand its typed controls to ``submit`` (a
    session's, off the event loop: it resolves the styles) and return the ``ack``; ControlError (one line) for a bad
    field, a message over the rate limit, or with the session's own words for what only the model can refuse (a
    style or gesture it does not know)."""
    controls = message_controls(message)
    rate.admit(controls)
    try:
        notes = await asyncio.to_thread(submit, controls)
    except (UserError, ValueError) as error:  # ControlError and CueRefused are UserErrors
        raise ControlError(str(error)) from None
    return ack(controls, notes)


def ack(controls: tuple[Control, ...], notes: dict | None = None) -> str:
    """The answer to a control; ``notes`` add what the session tells of it (when a gesture's stroke shows)."""
    return json.dumps({"type": "ack", "applied": acknowledged(controls), **(notes or {})})
