"""Access rules of the WebSocket ports: token sources and strength, origin lists, the wrong-token window."""

from types import SimpleNamespace

import pytest
from websockets.datastructures import Headers

from gesturecast.bridges.ws_access import (
    MAX_TOKEN_FAILURES,
    TOKEN_ENV_VAR,
    TOKEN_FAILURE_WINDOW_S,
    AccessPolicy,
    FailedTokens,
    WrongToken,
    check_origins,
    check_token_strength,
    client_key,
    token_from_sources,
    tokens_match,
)
from gesturecast.errors import UserError
from gesturecast.realtime.timing.clock import FakeClock

TOKEN = "pässwörd-日本語-токен-✓"


def test_token_sources_file_then_flag_then_environment(tmp_path):
    path = tmp_path / "token"
    path.write_text(f"  {TOKEN}\n", encoding="utf-8")
    environ = {TOKEN_ENV_VAR: "from-the-environment"}
    assert token_from_sources(None, path, environ) == TOKEN
    assert token_from_sources("from-the-flag", None, environ) == "from-the-flag"
    assert token_from_sources(None, None, environ) == "from-the-environment"
    assert token_from_sources(None, None, {}) is None
    assert token_from_sources(None, None, {TOKEN_ENV_VAR: ""}) is None


@pytest.mark.parametrize(
    ("flag", "file_text", "message"),
    [("x", "y", "not both"), (None, "\n", "is empty"), (None, None, "cannot read the token file"),
     (None, "t" * 4097, "holds more than 4 KiB")],
)
def test_bad_token_sources_are_one_line_errors(tmp_path, flag, file_text, message):
    path = tmp_path / "token"
    if file_text is not None:
        path.write_text(file_text, encoding="utf-8")
    with pytest.raises(UserError, match=message) as error:
        token_from_sources(flag, path, {})
    assert "\n" not in str(error.value)


def test_strength_and_unicode_comparison():
    check_token_strength(TOKEN)
    for weak in ("short", "aaaaaaaaaaaaaaaaaaaa", "abababababababababab"):
        with pytest.raises(UserError, match="at least 16 characters with at least 8 different"):
            check_token_strength(weak)
    assert tokens_match(TOKEN, TOKEN)
    assert not tokens_match(TOKEN[:-1], TOKEN) and not tokens_match(None, TOKEN) and not tokens_match(7, TOKEN)
    assert not tokens_match("\ud800", TOKEN)  # a lone surrogate from JSON compares, never raises


def test_allowed_origins_are_normalised_and_checked():
    assert check_origins(["HTTP://LocalHost:3000/", "https://example.org"]) == (
        "http://localhost:3000", "https://example.org")
    for bad in ("localhost:3000", "ftp://example.org", "http://example.org/page", "*"):
        with pytest.raises(UserError, match="--allow-origin"):
            check_origins([bad])


def test_an_address_is_blocked_after_the_limit_until_the_window_passes():
    clock = FakeClock()
    failures = FailedTokens(clock.now)
    for _ in range(MAX_TOKEN_FAILURES - 1):
        failures.record("10.0.0.1")
        clock.advance(1.0)
    assert not failures.blocked("10.0.0.1")
    failures.record("10.0.0.1")
    assert failures.blocked("10.0.0.1") and not failures.blocked("10.0.0.2")
    clock.advance(TOKEN_FAILURE_WINDOW_S - MAX_TOKEN_FAILURES + 1.0)  # the first failure is a window old
    assert not failures.blocked("10.0.0.1")


def peer(address: str, **headers: str) -> SimpleNamespace:
    """A connection's stand-in: its peer address and its handshake's headers."""
    request = SimpleNamespace(headers=Headers([(name.replace("_", "-"), value) for name, value in headers.items()]))
    return SimpleNamespace(remote_address=(address, 50000), local_address=("127.0.0.1", 8766), request=request)


def test_clients_on_this_machine_are_told_apart_by_their_proxys_address_or_their_user_agent():
    remote = peer("203.0.113.7", X_Forwarded_For="10.9.9.9")  # a remote peer's own header is not believed
    assert client_key(remote, remote.request.headers) == "203.0.113.7"
    proxied = peer("127.0.0.1", X_Forwarded_For="6.6.6.6, 198.51.100.4")  # the client forged the first entry
    assert client_key(proxied, proxied.request.headers) == "198.51.100.4"  # the proxy appended the last
    app = peer("::1", User_Agent="obs-plugin/2")
    assert client_key(app, app.request.headers) == "::1 obs-plugin/2"


def test_five_wrong_tokens_from_one_local_app_lock_out_that_app_only():
    """Five wrong tokens from 127.0.0.1 locked out every new local connection (every app, every proxied client)."""
    clock = FakeClock()
    policy = AccessPolicy("127.0.0.1", "s3cret-token-0123456789", (), clock.now)
    bad, good = peer("127.0.0.1", User_Agent="bad-app/1"), peer("127.0.0.1", User_Agent="good-app/1")
    proxied = peer("127.0.0.1", User_Agent="bad-app/1", X_Forwarded_For="198.51.100.4")
    for _ in range(MAX_TOKEN_FAILURES):
        with pytest.raises(WrongToken):
            policy.verify_token(bad, {"token": "guess-guess-guess-guess"})
    assert policy.process_request(bad, bad.request).status_code == 429
    assert policy.process_request(good, good.request) is None
    assert policy.process_request(proxied, proxied.request) is None
