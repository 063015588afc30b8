import numpy as np
import onnx
import torch
from onnx import TensorProto

from gesturecast.models.export.onnx_half import MIN_ELEMENTS, round_weights_to_half, store_weights_in_half
from gesturecast.models.runtime.ort_session import make_session

WIDTH = 64


def export_mlp(model: torch.nn.Module, path) -> None:
    with torch.no_grad():
        torch.onnx.export(model, (torch.zeros(1, WIDTH),), str(path), input_names=["x"], output_names=["y"],
                          dynamo=False)


def run(path, x: np.ndarray) -> np.ndarray:
    return make_session(path).run(None, {"x": x})[0]


def test_half_storage_halves_the_file_and_runs_as_the_rounded_float32_model(tmp_path):
    torch.manual_seed(0)
    model = torch.nn.Sequential(torch.nn.Linear(WIDTH, WIDTH), torch.nn.GELU(), torch.nn.Linear(WIDTH, 3))
    x = np.random.default_rng(0).standard_normal((1, WIDTH)).astype(np.float32)
    export_mlp(model, tmp_path / "full.onnx")
    round_weights_to_half(model)
    export_mlp(model, tmp_path / "rounded.onnx")
    export_mlp(model, tmp_path / "half.onnx")
    store_weights_in_half(tmp_path / "half.onnx")

    stored = onnx.load(str(tmp_path / "half.onnx")).graph.initializer
    large = [init for init in stored if int(np.prod(init.dims)) >= MIN_ELEMENTS]
    assert large and all(init.data_type == TensorProto.FLOAT16 for init in large)
    assert (tmp_path / "half.onnx").stat().st_size < 0.6 * (tmp_path / "full.onnx").stat().st_size
    np.testing.assert_array_equal(run(tmp_path / "half.onnx", x), run(tmp_path / "rounded.onnx", x))
    assert not np.array_equal(run(tmp_path / "full.onnx", x), run(tmp_path / "rounded.onnx", x))  # rounding is real
    with torch.no_grad():
        np.testing.assert_allclose(run(tmp_path / "half.onnx", x), model(torch.as_tensor(x)).numpy(), atol=1e-6)
