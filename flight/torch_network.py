"""A bundle's coefficient graph run by torch, on a CPU or a GPU: the torch backend's coefficients, rebuilt from the
bundle's ONNX file alone (no training code, no model class): the graph's nodes are run in order on torch tensors,
its initializers the weights. Checked against ONNX Runtime on the bundle checker's probe set before it is used.

Imported only where torch is asked for (`flight.torch_engine`): the serving install has neither torch nor onnx."""

from __future__ import annotations

import os
from collections.abc import Callable

import numpy as np
import onnx
import torch
from golfflight.flight.bundle_check import open_verified, probe_set
from golfflight.weights_schema.bundle import BundleError
from golfflight.weights_schema.model_card import ModelCard
from onnx import numpy_helper

PARITY_TOLERANCE = 1e-5
"""Largest |ONNX Runtime - torch| / max(1, |ONNX Runtime|) the rebuilt graph's coefficients may differ by on the
probe set (float32 rounding: the probes include a ball at rest, whose spin ratio the graph guards to ~1e12)."""


def _gemm(a, b, c=None, alpha: float = 1.0, beta: float = 1.0, transA: int = 0, transB: int = 0):  # noqa: N803
    if transB and not transA and alpha == 1.0 and beta == 1.0:
        return torch.nn.functional.linear(a, b, c)  # a layer as torch.nn.Linear runs it: one fused kernel
    product = alpha * ((a.T if transA else a) @ (b.T if transB else b))
    return product if c is None else product + beta * c


def _clip(x, low=None, high=None, min=None, max=None):  # noqa: A002 - ONNX's attribute names (opset < 11)
    low = min if low is None else low
    high = max if high is None else high
    return torch.clamp(x, low, high)


def _reduce_l2(x, axes=None, keepdims: int = 1):
    return torch.linalg.vector_norm(x, dim=tuple(axes) if axes is not None else None, keepdim=bool(keepdims))


def _reduce_sum(x, axes=None, keepdims: int = 1, noop_with_empty_axes: int = 0):
    dims = tuple(axes.tolist() if isinstance(axes, torch.Tensor) else axes) if axes is not None else None
    return x if dims is None and noop_with_empty_axes else torch.sum(x, dim=dims, keepdim=bool(keepdims))


OPS: dict[str, Callable] = {
    "Gemm": _gemm,
    "MatMul": torch.matmul,
    "Add": torch.add,
    "Sub": torch.sub,
    "Mul": torch.mul,
    "Div": torch.div,
    "Pow": torch.pow,
    "Neg": torch.neg,
    "Abs": torch.abs,
    "Sqrt": torch.sqrt,
    "Exp": torch.exp,
    "Log": torch.log,
    "Relu": torch.relu,
    "Sigmoid": torch.sigmoid,
    "Tanh": torch.tanh,
    "Softplus": torch.nn.functional.softplus,
    "Clip": _clip,
    "Min": lambda *x: torch.stack(torch.broadcast_tensors(*x)).amin(0),
    "Max": lambda *x: torch.stack(torch.broadcast_tensors(*x)).amax(0),
    "ReduceL2": _reduce_l2,
    "ReduceSum": _reduce_sum,
    "Concat": lambda *x, axis: torch.cat(x, dim=axis),
    "Identity": lambda x: x,
}
"""The ONNX operators a coefficient graph may use, each as torch runs it (inputs positional, attributes by name)."""


class GraphNetwork(torch.nn.Module):
    """(v_rel [N,3], omega [N,3]) float32 -> [N,4] C_L, C_D, C_M, C_Q: the graph's nodes on torch tensors."""

    def __init__(self, graph: onnx.GraphProto) -> None:
        super().__init__()
        unknown = sorted({node.op_type for node in graph.node} - set(OPS) - {"Constant"})
        if unknown:
            raise BundleError(f"the graph uses {', '.join(unknown)}: not an operator the torch backend runs "
                              f"({', '.join(sorted(OPS))}); fly it with backend='onnx'")
        self.inputs = [spec.name for spec in graph.input]
        self.output = graph.output[0].name
        self.steps: list[tuple[str, list[str], list[str], dict]] = []
        values = {tensor.name: numpy_helper.to_array(tensor) for tensor in graph.initializer}
        for node in graph.node:
            attributes = {a.name: onnx.helper.get_attribute_value(a) for a in node.attribute}
            if node.op_type == "Constant":
                values[node.output[0]] = numpy_helper.to_array(attributes["value"])
            else:
                self.steps.append((node.op_type, list(node.input), list(node.output), attributes))
        self.names = list(values)
        for index, name in enumerate(self.names):
            self.register_buffer(f"value_{index}", torch.from_numpy(np.array(values[name])).clone())  # torch-aligned
        last_use = {name: i for i, (_, inputs, _, _) in enumerate(self.steps) for name in inputs}
        self.done_after = [[name for name in dict.fromkeys(inputs) if name and last_use[name] == i and name not in values
                            and name != self.output] for i, (_, inputs, _, _) in enumerate(self.steps)]
        """The intermediate values each step reads for the last time: let go of at once, as a torch module's layers
        let go of theirs (holding every activation to the end cost about 8 % on a CPU: more memory, colder caches)."""

    def forward(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        held = {name: getattr(self, f"value_{index}") for index, name in enumerate(self.names)}
        held.update(zip(self.inputs, (v_rel, omega), strict=True))
        for (op, inputs, outputs, attributes), done in zip(self.steps, self.done_after, strict=True):
            arguments = [held[name] if name else None for name in inputs]
            while arguments and arguments[-1] is None:
                arguments.pop()
            held[outputs[0]] = OPS[op](*arguments, **attributes)
            for name in done:
                del held[name]
        return held[self.output]


def network_from_bundle(bundle_dir: str | os.PathLike, device: str | torch.device = "cpu") -> tuple[GraphNetwork,
                                                                                                     ModelCard]:
    """The bundle's coefficient graph as a torch module on `device` (eval mode, float32 as the graph runs) and its
    card, after the bundle's own checks (`flight.bundle_check`); BundleError where the graph uses an operator this
    does not run or its coefficients differ from ONNX Runtime's by more than PARITY_TOLERANCE on the probe set."""
    card, onnx_path, session = open_verified(bundle_dir)
    network = GraphNetwork(onnx.load(str(onnx_path)).graph).eval()
    velocity, spin = probe_set()
    names = [spec.name for spec in card.onnx.inputs]
    expected = session.run(None, dict(zip(names, (velocity, spin), strict=True)))[0]
    with torch.no_grad():
        got = network(torch.from_numpy(velocity), torch.from_numpy(spin)).numpy()
    difference = float(np.max(np.abs(got - expected) / np.maximum(1.0, np.abs(expected))))
    if not difference <= PARITY_TOLERANCE:
        raise BundleError(f"{onnx_path}: the graph run by torch differs from ONNX Runtime by {difference:.3g}")
    return network.to(device), card
