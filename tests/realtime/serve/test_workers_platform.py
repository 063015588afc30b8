"""`serve --workers` says plainly that it runs on Linux only, on macOS (which has ``socket.send_fds``) too."""

from __future__ import annotations

import pytest

from gesturecast.errors import UserError
from gesturecast.realtime.serve import workers


@pytest.mark.parametrize("platform", ["darwin", "win32"])
def test_workers_refuse_other_platforms_in_one_line(monkeypatch, platform):
    monkeypatch.setattr(workers.sys, "platform", platform)
    with pytest.raises(UserError, match=f"Linux only \\(this is {platform}\\)") as error:
        workers.listen_port("127.0.0.1", 0)
    assert "\n" not in str(error.value)


def test_workers_listen_on_linux(monkeypatch):
    monkeypatch.setattr(workers.sys, "platform", "linux")
    with workers.listen_port("127.0.0.1", 0) as listener:
        assert listener.getsockname()[1] > 0
