"""The model variants of Table 1: Phys-NN family (MLP coefficients), Phys-Q (quadratic in S) and NN (launch -> landing).

Every physics variant is a torch module with `coefficients(v_rel, omega) -> [N,4]` = C_L, C_D, C_M, C_Q, the same
contract as `flight.physics.CoefficientModel` and as the exported ONNX graph.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import torch
from golfflight.errors import InputError
from golfflight.flight.coefficients import BASE_DYNAMIC_PRESSURE, FERGUSON_2022
from golfflight.flight.physics import spin_ratio, spin_ratio_of
from golfflight.model_export import DEFAULT_HIDDEN, PHYS_NN_VARIANTS, VARIANTS
from torch import nn

VELOCITY_SCALE_MPS = 89.4
"""MLP input normalisation (paper section 2.2): 200 mph."""

SPIN_SCALE_RADPS = 2094.0
"""MLP input normalisation: 20,000 rpm."""

LANDING_SCALE_M = 100.0
"""The NN baseline's outputs are in units of 100 m, so its initial outputs are within range of the targets."""

P_M_INIT = 0.01
"""Start value of p_M in C_M = p_M S: measured C_M ~ 0.010-0.012 S (Smits; Tavares 1999)."""


def mlp(n_in: int, hidden: Sequence[int], n_out: int) -> nn.Sequential:
    """Fully connected ReLU network n_in -> hidden... -> n_out (no activation on the output)."""
    layers: list[nn.Module] = []
    for width in hidden:
        layers += [nn.Linear(n_in, width), nn.ReLU()]
        n_in = width
    layers.append(nn.Linear(n_in, n_out))
    return nn.Sequential(*layers)


def normalised_input(velocity: torch.Tensor, spin: torch.Tensor) -> torch.Tensor:
    """[v / 89.4, omega / 2094]: the paper's MLP input (6 values), bounded by about 1 for golf shots."""
    return torch.cat([velocity / VELOCITY_SCALE_MPS, spin / SPIN_SCALE_RADPS], dim=-1)


def speed_and_spin_rate(v_rel: torch.Tensor, omega: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
    """|v_rel| and |omega| [N, 1]: the coefficient MLP's input, scaled by 89.4 m/s and 2094 rad/s.

    A spinning sphere's coefficients depend on the Reynolds number and spin ratio, i.e. on these two magnitudes
    at a given air, not on the direction of flight. The paper feeds the 6 components instead; that lets the
    net tell a slice from a hook (mirrored shots landed up to 14.7 m apart), so we feed the invariants."""
    return torch.linalg.vector_norm(v_rel, dim=-1, keepdim=True), torch.linalg.vector_norm(omega, dim=-1, keepdim=True)


class CoefficientModule(nn.Module):
    """A torch coefficient model; `forward` is `coefficients` so the module itself is the ONNX graph."""

    variant: str

    def coefficients(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        raise NotImplementedError

    def forward(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        return self.coefficients(v_rel, omega)


class PhysNN(CoefficientModule):
    """Phys-NN family: an MLP on |v_rel| and |omega| (`speed_and_spin_rate`). Heads are raw features h; C_L = sigma(h)/2, C_D = sigma(h)/2, then either
    C_M = sigma(h)/50 (own head) or C_M = p_M S (pM), and C_Q = sigma(h) (cQ) or the constant 0.5."""

    def __init__(self, variant: str, hidden: Sequence[int] = DEFAULT_HIDDEN):
        super().__init__()
        if variant not in PHYS_NN_VARIANTS:
            raise InputError(f"unknown Phys-NN variant {variant!r}; choose from {PHYS_NN_VARIANTS}")
        self.variant = variant
        self.hidden = tuple(int(h) for h in hidden)
        self.learned_moment = variant != "phys-nn"
        self.learned_pressure = variant in ("phys-nn-pm-cq", "phys-nn+")
        self.heads = (
            ("C_L", "C_D") + (("C_Q",) if self.learned_pressure else ()) + (() if self.learned_moment else ("C_M",))
        )
        self.net = mlp(2, self.hidden, len(self.heads))
        if self.learned_moment:
            self.log_p_m = nn.Parameter(torch.tensor(math.log(P_M_INIT)))

    @property
    def p_m(self) -> torch.Tensor:
        """p_M = exp(log_p_m): positive by construction, and Adam moves it by relative steps."""
        return self.log_p_m.exp()

    def coefficients(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        speed, spin_rate = speed_and_spin_rate(v_rel, omega)  # once: the MLP and S = R |omega| / |v_rel| share them
        out = torch.sigmoid(self.net(torch.cat([speed / VELOCITY_SCALE_MPS, spin_rate / SPIN_SCALE_RADPS], dim=-1)))
        c_lift, c_drag = out[:, 0] / 2, out[:, 1] / 2
        if self.learned_moment:
            c_moment = self.p_m * spin_ratio_of(speed[:, 0], spin_rate[:, 0])
        else:
            c_moment = out[:, 2] / 50
        c_q = out[:, 2] if self.learned_pressure else torch.full_like(c_lift, BASE_DYNAMIC_PRESSURE)
        return torch.stack([c_lift, c_drag, c_moment, c_q], dim=-1)


class PhysQ(CoefficientModule):
    """Phys-Q baseline: C_L = max(0, p0 + p1 S + p2 S^2), C_D = p3 + p4 S + p5 S^2, C_M = p6 S, started from
    Ferguson et al. 2022; the same formulas as `flight.coefficients.QuadraticSpinRatio`."""

    variant = "phys-q"

    def __init__(self, params: Sequence[float] = FERGUSON_2022, dtype: torch.dtype = torch.float32):
        super().__init__()
        self.params = nn.Parameter(torch.tensor([float(p) for p in params], dtype=dtype))

    def coefficients(self, v_rel: torch.Tensor, omega: torch.Tensor) -> torch.Tensor:
        p = self.params.to(v_rel.dtype)
        s = spin_ratio(v_rel, omega)
        c_lift = (p[0] + p[1] * s + p[2] * s**2).clamp_min(0.0)
        c_drag = p[3] + p[4] * s + p[5] * s**2
        return torch.stack([c_lift, c_drag, p[6] * s, torch.full_like(s, BASE_DYNAMIC_PRESSURE)], dim=-1)


class LandingNN(nn.Module):
    """NN baseline (paper eq. 23): launch velocity and spin -> landing point (x, y) in m, no physics.
    It has no coefficient graph, so it is trained and evaluated in torch only and cannot be exported."""

    variant = "nn"

    def __init__(self, hidden: Sequence[int] = DEFAULT_HIDDEN):
        super().__init__()
        self.hidden = tuple(int(h) for h in hidden)
        self.net = mlp(6, self.hidden, 2)

    def forward(self, velocity0: torch.Tensor, spin0: torch.Tensor) -> torch.Tensor:
        return LANDING_SCALE_M * self.net(normalised_input(velocity0, spin0))


def build_model(variant: str, hidden: Sequence[int] = DEFAULT_HIDDEN) -> nn.Module:
    """A freshly initialised model of a variant (Phys-Q ignores `hidden`: it has no network)."""
    if variant in PHYS_NN_VARIANTS:
        return PhysNN(variant, hidden)
    if variant == "phys-q":
        return PhysQ()
    if variant == "nn":
        return LandingNN(hidden)
    raise InputError(f"unknown variant {variant!r}; choose from {VARIANTS}")
