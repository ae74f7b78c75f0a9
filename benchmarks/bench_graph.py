"""Where a single-shot step's time goes: ONNX Runtime's fixed cost per call, the cost per graph node, the physics.

For one row every graph node costs a fixed dispatch overhead, so the node count matters more than the network's
arithmetic (docs/benchmarks.md). This script times, one row through IOBinding as the engine calls them: a one-node
graph (the per-call floor), the bundle's network alone (its Gemms and sigmoid), the bundle's whole graph, and the
plain-float Euler step; then a whole 7-iron, to compare the parts with the sum.

python benchmarks/bench_graph.py [--model DIR]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import onnx
import onnxruntime as ort
from common import SEVEN_IRON, add_results_flag, write_results
from golfflight.flight.bundle_check import session_options
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import FlightEngine, FlightProblem
from golfflight.flight.physics import euler_step
from golfflight.weights_schema.bundle import load_bundle
from onnx import TensorProto, helper


def optimised_node_count(model: onnx.ModelProto) -> int:
    """Nodes left after ONNX Runtime's graph optimisations (fusions, constant folding), as the engine runs it."""
    with tempfile.TemporaryDirectory() as folder:
        options = session_options(1)
        options.optimized_model_filepath = str(Path(folder) / "optimised.onnx")
        options.log_severity_level = 3  # ORT warns that the saved graph is machine-specific: that is the point
        ort.InferenceSession(model.SerializeToString(), options, providers=["CPUExecutionProvider"])
        return len(onnx.load(options.optimized_model_filepath).graph.node)


def one_node_graph() -> onnx.ModelProto:
    """y = x + x: the least work a call can do, so its time is ORT's fixed cost per call."""
    x = helper.make_tensor_value_info("x", TensorProto.FLOAT, ["N", 2])
    y = helper.make_tensor_value_info("y", TensorProto.FLOAT, ["N", 2])
    graph = helper.make_graph([helper.make_node("Add", ["x", "x"], ["y"])], "floor", [x], [y])
    return helper.make_model(graph, opset_imports=[helper.make_opsetid("", 17)])


def network_only(model: onnx.ModelProto) -> onnx.ModelProto:
    """The bundle's MLP from its 2 features to its sigmoids: the graph minus the norms and the tail."""
    nodes = model.graph.node
    first = next(i for i, n in enumerate(nodes) if n.op_type == "Gemm")
    last = next(i for i, n in enumerate(nodes) if n.op_type == "Sigmoid")
    inferred = onnx.shape_inference.infer_shapes(model)
    return onnx.utils.Extractor(inferred).extract_model([nodes[first].input[0]], [nodes[last].output[0]])


def one_row_call_us(model: onnx.ModelProto, rounds: int = 9, calls: int = 5000) -> float:
    """Median time of one single-row call through IOBinding (one thread), in microseconds."""
    session = ort.InferenceSession(model.SerializeToString(), session_options(1), providers=["CPUExecutionProvider"])
    binding = session.io_binding()
    buffers = []
    for spec in (*session.get_inputs(), *session.get_outputs()):
        width = spec.shape[-1] if isinstance(spec.shape[-1], int) else 2
        buffers.append(np.full((1, width), 0.5, np.float32))
        bind = binding.bind_input if len(buffers) <= len(session.get_inputs()) else binding.bind_output
        bind(spec.name, "cpu", 0, np.float32, [1, width], buffers[-1].ctypes.data)
    return median_us(lambda: session.run_with_iobinding(binding), rounds, calls)


def median_us(call, rounds: int = 9, calls: int = 5000) -> float:
    for _ in range(calls // 10):
        call()
    timings = []
    for _ in range(rounds):
        started = time.perf_counter()
        for _ in range(calls):
            call()
        timings.append((time.perf_counter() - started) / calls * 1e6)
    return statistics.median(timings)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", help="model bundle (default: the shipped one)")
    add_results_flag(parser)
    args = parser.parse_args()
    bundle = model_dir(args.model)
    card, onnx_path = load_bundle(bundle)
    graph = onnx.load(str(onnx_path))
    parts = {"one-node graph (fixed cost per call)": one_node_graph(), "the network alone": network_only(graph),
             "the bundle's graph": graph}
    rows = []
    for name, model in parts.items():
        rows.append({"name": f"one-row ORT call, {name}", "unit": "us", "p50": one_row_call_us(model),
                     "nodes": len(model.graph.node), "nodes_after_ort": optimised_node_count(model)})
    state = (0.0, 30.0, 20.0, 5.0, 50.0, 10.0, 600.0, 0.0, -30.0)
    rows.append({"name": "plain-float Euler step (flight.physics.euler_step)", "unit": "us",
                 "p50": median_us(lambda: euler_step(*state, (0.2, 0.25, 0.001, 0.5), 1.225, 0.0, 0.0, 0.1))})
    engine = FlightEngine(bundle)
    steps = engine.fly(FlightProblem.of([SEVEN_IRON]))[0].flight_time_s / card.physics.dt_s
    shot_us = median_us(lambda: engine.fly(FlightProblem.of([SEVEN_IRON])), rounds=9, calls=300)
    rows.append({"name": f"whole 7-iron, per step ({steps:.0f} steps)", "unit": "us", "p50": shot_us / steps})
    print("| part of a step | nodes (after ORT) | time |")
    print("|---|---:|---:|")
    for row in rows:
        nodes = f"{row['nodes']} ({row['nodes_after_ort']})" if "nodes" in row else ""
        print(f"| {row['name']} | {nodes} | {row['p50']:.2f} us |")
    graph_us, floor_us = rows[2]["p50"], rows[0]["p50"]
    extra_nodes = rows[2]["nodes_after_ort"] - 1
    print(f"\nper extra node after the first: {(graph_us - floor_us) / extra_nodes:.2f} us; the rest of a step "
          f"(loop, buffers, landing checks): {rows[4]['p50'] - graph_us - rows[3]['p50']:.2f} us")
    write_results("graph_overhead", rows, args.results)


if __name__ == "__main__":
    main()
