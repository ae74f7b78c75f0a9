"""Broken model bundles are refused with a clear message by the engine, the service and every command, before
anything flies; the runtime path never unpickles anything."""

from __future__ import annotations

import ast
import json
import shutil
from pathlib import Path

import numpy as np
import onnx
import pytest
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import FlightEngine
from golfflight.flight.onnx_coefficients import OnnxCoefficients
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from golfflight.weights_schema.bundle import BundleError, sha256_of
from onnx import numpy_helper
from servers import running

from golfflight.cli import main

REPO = Path(__file__).resolve().parents[1]


def _copy(tmp_path: Path) -> Path:
    bundle = tmp_path / "bundle"
    shutil.copytree(model_dir(), bundle)
    return bundle


def _card(bundle: Path) -> dict:
    return json.loads((bundle / "model_card.json").read_text())


def _write_card(bundle: Path, card: dict) -> None:
    (bundle / "model_card.json").write_text(json.dumps(card))


def _rehash(bundle: Path) -> None:
    card = _card(bundle)
    card["onnx"]["sha256"] = sha256_of(bundle / "model.onnx")
    _write_card(bundle, card)


def _edit_graph(bundle: Path, edit) -> None:
    model = onnx.load(bundle / "model.onnx")
    edit(model.graph)
    onnx.save(model, bundle / "model.onnx")
    _rehash(bundle)


def card_not_json(bundle):
    (bundle / "model_card.json").write_text('{"schema_version": "1.1", "variant": ')


def card_invalid(bundle):
    card = _card(bundle)
    del card["physics"]["dt_s"]
    card["physics"]["gravity_mps2"] = -9.81
    _write_card(bundle, card)


def card_unknown_schema(bundle):
    _write_card(bundle, {**_card(bundle), "schema_version": "9.0"})


def onnx_changed(bundle):
    data = bytearray((bundle / "model.onnx").read_bytes())
    data[len(data) // 2] ^= 0xFF
    (bundle / "model.onnx").write_bytes(bytes(data))


def onnx_half_written(bundle):
    data = (bundle / "model.onnx").read_bytes()
    (bundle / "model.onnx").write_bytes(data[: len(data) // 2])


def onnx_not_a_graph_but_hashed(bundle):
    (bundle / "model.onnx").write_bytes(b"\x08\x07garbage that is not a protobuf graph" * 10)
    _rehash(bundle)


def onnx_input_renamed(bundle):
    def rename(graph):
        old, new = graph.input[0].name, "velocity"
        graph.input[0].name = new
        for node in graph.node:
            for i, name in enumerate(node.input):
                if name == old:
                    node.input[i] = new

    _edit_graph(bundle, rename)


def card_output_shape(bundle):
    card = _card(bundle)
    card["onnx"]["outputs"][0]["shape"] = ["N", 3]
    _write_card(bundle, card)


def card_input_names_swapped(bundle):
    card = _card(bundle)
    card["onnx"]["inputs"] = card["onnx"]["inputs"][::-1]
    _write_card(bundle, card)


def weights_give_nan(bundle):
    def poison(graph):
        biggest = max(graph.initializer, key=lambda t: int(np.prod(t.dims)))
        values = numpy_helper.to_array(biggest).copy()
        values.flat[0] = np.nan
        biggest.CopyFrom(numpy_helper.from_array(values, biggest.name))

    _edit_graph(bundle, poison)


FAULTS = {
    card_not_json: "not valid JSON",
    card_invalid: "invalid model card",
    card_unknown_schema: "schema_version '9.0' is not one this golfflight reads",
    onnx_changed: "does not match the card",
    onnx_half_written: "does not match the card",
    onnx_not_a_graph_but_hashed: "ONNX Runtime cannot load it",
    onnx_input_renamed: "are not the card's",
    card_output_shape: "the engine reads ['N', 4]",
    card_input_names_swapped: "are not the card's",
    weights_give_nan: "non-finite or misshapen coefficients on the probe set",
}


@pytest.fixture(params=list(FAULTS), ids=[f.__name__ for f in FAULTS])
def broken(request, tmp_path):
    bundle = _copy(tmp_path)
    request.param(bundle)
    return bundle, FAULTS[request.param]


def test_the_shipped_bundle_passes_every_check():
    assert FlightEngine(model_dir()).variant


def test_engine_and_coefficient_model_refuse_a_broken_bundle(broken):
    bundle, expected = broken
    for load in (FlightEngine, OnnxCoefficients):
        with pytest.raises(BundleError) as error:
            load(bundle)
        assert expected in str(error.value) and str(bundle) in str(error.value)


def test_commands_refuse_a_broken_bundle_in_one_line(broken, tmp_path, capsys):
    bundle, expected = broken
    shots = tmp_path / "shots.json"
    shots.write_text(json.dumps([{"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100}]))
    for argv in (["serve", "--model", str(bundle), "--port", "9"], ["simulate", str(shots), "--model", str(bundle)]):
        assert main(argv) == 2
        captured = capsys.readouterr()
        assert expected in captured.err and "Traceback" not in captured.err
        assert captured.err.startswith(f"golfflight {argv[0]}: error: ")
        assert "golfflight serve:" not in captured.out  # never got as far as starting


def test_the_service_reports_a_broken_bundle_on_healthz_and_flies_nothing(tmp_path):
    bundle = _copy(tmp_path)
    weights_give_nan(bundle)
    with running(create_app(ServiceSettings(model=bundle))) as http:
        health = http.get("/healthz")
        assert health.status_code == 503 and health.json()["status"] == "failed"
        assert "non-finite" in health.json()["error"]
        shot = http.post("/v1/shots", json={"ball_speed_mps": 55, "launch_angle_deg": 16, "spin_rpm": 7100})
        assert shot.status_code == 503


RUNTIME = ["service", "weights_schema", "shots", "golfflight/cli.py", "golfflight/commands/serve.py",
           "golfflight/commands/simulate.py", "golfflight/commands/simulate_io.py", "golfflight/commands/fly.py"]
UNPICKLERS = {"pickle", "cPickle", "dill", "joblib", "cloudpickle", "shelve", "marshal", "torch"}


def _unpickling_calls(path: Path) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [f"import {a.name}" for a in node.names if a.name.split(".")[0] in UNPICKLERS]
        elif isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] in UNPICKLERS:
            found.append(f"from {node.module} import ...")
        elif isinstance(node, ast.Call):
            text = ast.unparse(node.func)
            if text.endswith(("torch.load", "pickle.load", "pickle.loads")):
                found.append(text)
            if text.endswith(("np.load", "numpy.load")) and any(k.arg == "allow_pickle" for k in node.keywords):
                found.append(f"{text}(allow_pickle=...)")
    return [f"{path.relative_to(REPO)}: {f}" for f in found]


def test_no_pickle_or_torch_load_in_the_runtime_path():
    paths = [REPO / entry for entry in RUNTIME]
    files = [p for path in paths for p in (path.rglob("*.py") if path.is_dir() else [path])]
    assert len(files) > 20
    assert [f for path in files for f in _unpickling_calls(path)] == []
