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
