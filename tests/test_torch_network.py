"""The torch backend's coefficients (`flight.torch_network`): a bundle's ONNX graph run by torch without any training
code gives ONNX Runtime's coefficients; a graph with an operator it does not run is refused naming it; and
`FlightEngine.from_bundle` picks the backend."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")
onnx = pytest.importorskip("onnx")

from golfflight.errors import InputError
from golfflight.flight.bundle_check import open_verified
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.problem import FlightProblem
from golfflight.flight.torch_engine import TorchEngine
from golfflight.flight.torch_network import GraphNetwork, network_from_bundle
from golfflight.weights_schema.bundle import BundleError

from tests.test_imports import ROOT, imported

BUNDLES = ["default", "real", "synthetic"]


@pytest.mark.parametrize("name", BUNDLES)
def test_the_graph_run_by_torch_gives_onnx_runtimes_coefficients(name):
    bundle = ROOT / "models" / name
    network, card = network_from_bundle(bundle)
    _, _, session = open_verified(bundle)
    rng = np.random.default_rng(0)
    velocity = (rng.normal(0, 1, (2000, 3)) * [3, 40, 15]).astype(np.float32)
    spin = (rng.normal(0, 1, (2000, 3)) * [400, 5, 150]).astype(np.float32)
    expected = session.run(None, {card.onnx.inputs[0].name: velocity, card.onnx.inputs[1].name: spin})[0]
    with torch.no_grad():
        got = network(torch.from_numpy(velocity), torch.from_numpy(spin)).numpy()
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-6)


def test_a_graph_with_an_operator_torch_does_not_run_is_refused_naming_it():
    graph = onnx.load(str(ROOT / "models" / "default" / "model.onnx")).graph
    graph.node[4].op_type = "Erf"
    with pytest.raises(BundleError, match="the graph uses Erf: not an operator the torch backend runs"):
        GraphNetwork(graph)


def test_no_training_code_in_the_torch_backend():
    for module in ("torch_network.py", "torch_engine.py", "rollout.py", "devices.py"):
        names = imported(ROOT / "flight" / module)
        assert not [n for n in names if n.startswith("golfflight.model_export")], module
        assert "onnx" not in names or module == "torch_network.py"


def test_from_bundle_picks_the_backend():
    bundle = ROOT / "models" / "default"
    onnx_engine = FlightEngine.from_bundle(bundle)
    torch_engine = FlightEngine.from_bundle(bundle, backend="torch", dtype="float64")
    assert type(onnx_engine) is FlightEngine and isinstance(torch_engine, TorchEngine)
    assert onnx_engine.sha256 == torch_engine.sha256
    launches = np.array([Launch(55.0, 16.0, 0.0, 7100.0, 0.0), Launch(76.5, 10.5, 1.0, 2550.0, -3.0)])
    want, got = onnx_engine.fly_batch(FlightProblem.of(launches)), torch_engine.fly_batch(FlightProblem.of(launches))
    np.testing.assert_allclose(got.carry_m, want.carry_m, rtol=0, atol=1e-3)  # torch CPU parity: 1 mm
    with pytest.raises(InputError, match="backend 'jax': choose onnx or torch"):
        FlightEngine.from_bundle(bundle, backend="jax")
    with pytest.raises(InputError, match="the onnx backend runs on the cpu"):
        FlightEngine.from_bundle(bundle, device="cuda")
