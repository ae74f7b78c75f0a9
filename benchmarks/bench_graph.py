"""Where a single-shot step's time goes: the bundle's ONNX graph against an equivalent lean graph.

The exported Phys-NN+ graph is 23 nodes after ONNX Runtime's optimisations: the MLP (3 fused Gemms) plus ~18
small nodes (input scaling, Split/Squeeze/Unsqueeze/Concat of the heads, p_M S). For one row every node costs
a fixed dispatch overhead, so those small nodes cost more than the network. This script rebuilds the same
function from the bundle's weights in 14 nodes, 11 after ORT's fusions (input scaling folded into the first
Gemm, the heads scaled by one Mul, p_M S added as one row) and times both through IOBinding, as the engine
calls them. Evidence for the exporter, not used at runtime: the engine serves the bundle's graph as shipped.

python benchmarks/bench_graph.py [--model DIR]   (phys-nn+ bundles only)
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import onnx
import onnxruntime as ort
from common import write_results
from onnx import TensorProto, helper, numpy_helper

from service.constants import BALL_RADIUS_M
from service.model_location import model_dir
from weights_schema.bundle import load_bundle


def lean_graph(card, onnx_path) -> onnx.ModelProto:
    """The phys-nn+ coefficient function of `onnx_path` as a 14-node graph with the same inputs and output."""
    weights = {i.name: numpy_helper.to_array(i) for i in onnx.load(str(onnx_path)).graph.initializer}
    scale = np.array([1 / 89.4] * 3 + [1 / 2094.0] * 3, np.float32)
    head_w, head_b = np.zeros((4, weights["net.4.weight"].shape[1]), np.float32), np.zeros(4, np.float32)
    head_w[[0, 1, 3]], head_b[[0, 1, 3]] = weights["net.4.weight"], weights["net.4.bias"]
    constants = {
        "w0": (weights["net.0.weight"] * scale).astype(np.float32),
        "b0": weights["net.0.bias"],
        "w1": weights["net.2.weight"],
        "b1": weights["net.2.bias"],
        "w2": head_w,
        "b2": head_b,
        "heads": np.array([0.5, 0.5, 0.0, 1.0], np.float32),
        "moment": np.array([0.0, 0.0, BALL_RADIUS_M * card.architecture.p_m, 0.0], np.float32),
        "tiny": np.array(1e-12, np.float32),
        "axes": np.array([-1], np.int64),
    }
    node = helper.make_node
    nodes = [
        node("Concat", ["v_rel", "omega"], ["x"], axis=-1),
        node("Gemm", ["x", "w0", "b0"], ["g0"], transB=1),
        node("Relu", ["g0"], ["r0"]),
        node("Gemm", ["r0", "w1", "b1"], ["g1"], transB=1),
        node("Relu", ["g1"], ["r1"]),
        node("Gemm", ["r1", "w2", "b2"], ["g2"], transB=1),
        node("Sigmoid", ["g2"], ["s"]),
        node("Mul", ["s", "heads"], ["c"]),
        node("ReduceL2", ["omega", "axes"], ["w_norm"], keepdims=1),
        node("ReduceL2", ["v_rel", "axes"], ["v_norm"], keepdims=1),
        node("Clip", ["v_norm", "tiny"], ["v_safe"]),
        node("Div", ["w_norm", "v_safe"], ["ratio"]),
        node("Mul", ["ratio", "moment"], ["c_m"]),
        node("Add", ["c", "c_m"], ["coefficients"]),
    ]
    inputs = [helper.make_tensor_value_info(n, TensorProto.FLOAT, ["N", 3]) for n in ("v_rel", "omega")]
    output = helper.make_tensor_value_info("coefficients", TensorProto.FLOAT, ["N", 4])
    initializers = [numpy_helper.from_array(a, n) for n, a in constants.items()]
    graph = helper.make_graph(nodes, "lean", inputs, [output], initializers)
    return helper.make_model(graph, opset_imports=[helper.make_opsetid("", 18)])


def one_row_call_us(model: bytes | str, rounds: int = 7, calls: int = 5000) -> float:
    options = ort.SessionOptions()
    options.intra_op_num_threads = options.inter_op_num_threads = 1
    session = ort.InferenceSession(model, options, providers=["CPUExecutionProvider"])
    buffers = [np.ones((1, 3), np.float32), np.full((1, 3), 300.0, np.float32), np.zeros((1, 4), np.float32)]
    binding = session.io_binding()
    for name, buffer in zip(("v_rel", "omega"), buffers[:2]):
        binding.bind_input(name, "cpu", 0, np.float32, [1, 3], buffer.ctypes.data)
    binding.bind_output("coefficients", "cpu", 0, np.float32, [1, 4], buffers[2].ctypes.data)
    timings = []
    for _ in range(rounds):
        started = time.perf_counter()
        for _ in range(calls):
            session.run_with_iobinding(binding)
        timings.append((time.perf_counter() - started) / calls * 1e6)
    return statistics.median(timings)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", help="model bundle (default: the shipped one)")
    args = parser.parse_args()
    card, onnx_path = load_bundle(model_dir(args.model))
    if card.variant != "phys-nn+":
        raise SystemExit(f"bench_graph.py rebuilds phys-nn+ graphs only, not {card.variant}")
    lean = lean_graph(card, onnx_path).SerializeToString()
    rng = np.random.default_rng(0)
    feeds = {
        "v_rel": rng.normal(0, 30, (4096, 3)).astype(np.float32),
        "omega": rng.normal(0, 300, (4096, 3)).astype(np.float32),
    }
    shipped = ort.InferenceSession(str(onnx_path), providers=["CPUExecutionProvider"]).run(None, feeds)[0]
    rebuilt = ort.InferenceSession(lean, providers=["CPUExecutionProvider"]).run(None, feeds)[0]
    difference = float(np.abs(shipped - rebuilt).max())
    bundle_us, lean_us = one_row_call_us(str(onnx_path)), one_row_call_us(lean)
    print("| graph | nodes (after ORT optimisation) | one-row call, IOBinding |")
    print("|---|---:|---:|")
    print(f"| the bundle's (as exported) | 23 | {bundle_us:.2f} us |")
    print(f"| equivalent lean graph (max |diff| {difference:.1g}) | 11 | {lean_us:.2f} us |")
    print(
        f"\nper 56-step 7-iron: {56 * (bundle_us - lean_us) / 1e3:.3f} ms of graph overhead"
        " that a lean export would save"
    )
    write_results(
        "graph_overhead",
        [
            {"name": "one-row ORT call, bundle graph", "unit": "us", "p50": bundle_us},
            {
                "name": "one-row ORT call, lean equivalent",
                "unit": "us",
                "p50": lean_us,
                "max_abs_difference": difference,
            },
        ],
    )


if __name__ == "__main__":
    main()
