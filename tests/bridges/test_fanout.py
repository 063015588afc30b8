import logging

from bridge_test_frames import moving_frame

from gesturecast.bridges.fanout import BridgeFanout


class Recording:
    def __init__(self, name: str) -> None:
        self.name = name
        self.seqs: list[int] = []
        self.closed = False

    def send(self, frame) -> None:
        self.seqs.append(frame.seq)

    def close(self) -> None:
        self.closed = True


class Broken(Recording):
    def send(self, frame) -> None:
        raise OSError("device unplugged")

    def close(self) -> None:
        raise OSError("already gone")


def test_a_failing_bridge_does_not_affect_the_others(caplog):
    first, broken, last = Recording("a"), Broken("broken"), Recording("b")
    fanout = BridgeFanout([first, broken, last])
    with caplog.at_level(logging.WARNING):
        for seq in range(4):
            fanout.send(moving_frame(seq))
        fanout.close()
    assert first.seqs == last.seqs == [0, 1, 2, 3]
    assert first.closed and last.closed
    assert fanout.failures() == {"a": 0, "broken": 5, "b": 0}
    lines = [r.getMessage() for r in caplog.records]
    assert len(lines) == 1 and "bridge 'broken' failed: device unplugged" in lines[0]



def test_counters_report_the_websocket_outbox_drops():
    """The live report's `outputs`: a real WebSocket bridge whose event loop is busy drops the oldest pending
    frames beyond its outbox and reports how many; bridges without delivery counters are left out."""
    import time

    from gesturecast.bridges.websocket_server import MAX_PENDING_FRAMES, WebSocketBridge, WebSocketConfig

    websocket = WebSocketBridge(WebSocketConfig(port=0)).start()
    fanout = BridgeFanout([Recording("a"), websocket])
    sent = 3 * MAX_PENDING_FRAMES
    try:
        websocket._listener.loop.call_soon_threadsafe(time.sleep, 0.5)  # the loop is busy: nothing drains
        for seq in range(sent):
            fanout.send(moving_frame(seq))
    finally:
        fanout.close()
    assert fanout.counters() == {"websocket": {"outbox_drops": sent - MAX_PENDING_FRAMES, "slow_client_skips": 0}}
