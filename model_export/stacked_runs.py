"""Several training runs of one network trained as one: each run's weights stacked along a leading axis, and the
network called on every run's shots at once (`torch.func.vmap`), so R runs dispatch about as many kernels as one.

Eager training is bound by its kernel launches on a GPU (one joint epoch dispatches 2.8 million ATen operations:
`benchmarks/bench_train.py`), so seeds flown side by side cost about what one seed costs there. A stacked run takes
the steps each run would take alone: its own minibatches, Adam moments (element-wise, so a stacked tensor's are each
run's) and gradient clipping (`clip_per_run`), up to float rounding.
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Iterator
from contextlib import contextmanager

import torch
from torch import nn
from torch.func import functional_call, stack_module_state, vmap
from golfflight.errors import InputError


class StackedNetworks:
    """`runs` copies of a coefficient module (`(v_rel, omega) -> [N, 4]`) trained side by side. Called on N = runs x n
    shots, run-major (run r's shots are rows r*n to (r+1)*n), each run's shots go through its own weights. One run
    is a copy of the module itself, with its own parameters (no run axis, no vmap): exactly the module's steps."""

    def __init__(self, module: nn.Module, runs: int) -> None:
        if runs < 1:
            raise InputError(f"runs must be at least 1, got {runs}")
        self.runs = runs
        self.base = copy.deepcopy(module)
        self.params, self.buffers = stack_module_state([module] * runs) if runs > 1 else ({}, {})

    def parameters(self) -> list[torch.Tensor]:
        """What the optimizer steps: the stacked parameters [runs, ...] in the module's order (one run: the copy's)."""
        return list(self.base.parameters()) if self.runs == 1 else list(self.params.values())

    def __call__(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        if self.runs == 1:
            return self.base(v_rel, omega)
        n = v_rel.shape[0] // self.runs

        def one_run(params: dict, buffers: dict, v: torch.Tensor, w: torch.Tensor) -> torch.Tensor:
            return functional_call(self.base, (params, buffers), (v, w))

        out = vmap(one_run)(self.params, self.buffers, v_rel.reshape(self.runs, n, -1),
                            omega.reshape(self.runs, n, -1))
        return out.reshape(self.runs * n, -1)

    def run_state(self, run: int) -> dict[str, torch.Tensor]:
        """Run `run`'s weights as the module's own state dict (what its checkpoint holds)."""
        if self.runs == 1:
            return {name: value.detach().clone() for name, value in self.base.state_dict().items()}
        stacked = self.params | self.buffers
        return {name: stacked[name][run].detach().clone() for name in self.base.state_dict()}

    def to(self, device: torch.device) -> StackedNetworks:
        self.base.to(device)
        self.params = {name: value.detach().to(device).requires_grad_() for name, value in self.params.items()}
        self.buffers = {name: value.to(device) for name, value in self.buffers.items()}
        return self


def run_of_rows(runs: int, rows: int, device: torch.device | None = None) -> torch.Tensor:
    """The run of each of runs x rows run-major rows [runs * rows]."""
    return torch.arange(runs, device=device).repeat_interleave(rows)


def clip_per_run(parameters: Iterable[torch.Tensor], max_norm: float, runs: int) -> None:
    """Scale each run's gradients so their joint 2-norm is at most `max_norm`, as `torch.nn.utils.clip_grad_norm_`
    does for one run's parameters (one run is left to it). Parameters are stacked [runs, ...]."""
    stepped = [p for p in parameters if p.grad is not None]
    if runs == 1:
        torch.nn.utils.clip_grad_norm_(stepped, max_norm)
        return
    grads = [p.grad for p in stepped]
    norms = torch.stack([torch.linalg.vector_norm(g.reshape(runs, -1), dim=1) for g in grads], dim=1)
    scale = (max_norm / (torch.linalg.vector_norm(norms, dim=1) + 1e-6)).clamp(max=1.0)
    for g in grads:
        g.mul_(scale.reshape(runs, *([1] * (g.dim() - 1))))


MOMENTS = ("exp_avg", "exp_avg_sq")
"""Adam's per-element state: what a held run keeps (`runs_held`)."""


@contextmanager
def runs_held(optimizer: torch.optim.Optimizer, held: torch.Tensor) -> Iterator[None]:
    """Around an optimizer step: the runs marked in `held` [runs] keep their weights and Adam moments, as a run
    alone keeps them when it skips a minibatch whose loss is not finite. (Adam's step count and the learning-rate
    schedule are shared by the stacked runs, so they move on for a held run too.)"""
    if not bool(held.any()):
        yield
        return
    kept = []
    for group in optimizer.param_groups:
        for p in group["params"]:
            state = optimizer.state.get(p, {})
            kept.append((p, p.detach()[held].clone(), {m: state[m][held].clone() for m in MOMENTS if m in state}))
    yield
    with torch.no_grad():
        for p, value, moments in kept:
            p[held] = value
            state = optimizer.state.get(p, {})
            for m in MOMENTS:
                if m in state:
                    state[m][held] = moments.get(m, 0.0)
