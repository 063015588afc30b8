import numpy as np
import onnx
import pytest
from onnx import TensorProto, helper

from gesturecast.models.runtime.ort_session import make_session, make_session_options


def _add_one_model() -> bytes:
    x = helper.make_tensor_value_info("x", TensorProto.FLOAT, [None, 3])
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, [None, 3])
    one = helper.make_tensor("one", TensorProto.FLOAT, [1], [1.0])
    graph = helper.make_graph([helper.make_node("Add", ["x", "one"], ["y"])], "add_one", [x], [y], [one])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])
    model.ir_version = 8
    onnx.checker.check_model(model)
    return model.SerializeToString()


def test_session_runs_from_bytes_and_path(tmp_path):
    data = _add_one_model()
    path = tmp_path / "add.onnx"
    path.write_bytes(data)
    x = np.arange(6, dtype=np.float32).reshape(2, 3)
    for source in (data, path, str(path)):
        (y,) = make_session(source, threads=2).run(None, {"x": x})
        np.testing.assert_array_equal(y, x + 1)


def test_options_disable_spinning_and_set_threads():
    options = make_session_options(threads=3)
    assert options.intra_op_num_threads == 3
    assert options.inter_op_num_threads == 1
    assert options.get_session_config_entry("session.intra_op.allow_spinning") == "0"
    with pytest.raises(ValueError):
        make_session_options(threads=0)
