"""Where each `train-real --variant` starts: Phys-NN+ from a bundle (`models/synthetic` by default), Phys-Q from
Ferguson et al. 2022's published coefficients as the paper refits them, NN from a fresh network (paper eq. 23).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING

from golfflight.errors import InputError
from golfflight.model_export import DEFAULT_HIDDEN
from golfflight.shots.paths import REPO_ROOT

if TYPE_CHECKING:
    from torch import nn

REAL_VARIANTS = ("phys-nn+", "phys-q", "nn")
"""The variants `train-real` trains on the real flights: the paper's model and its two baselines (Table 1)."""

DEFAULT_INIT = {"phys-nn+": str(REPO_ROOT / "models" / "synthetic")}
"""The bundle each variant starts from when `--init` is not given (the checkout's `models/synthetic`, wherever the
command runs); Phys-Q and NN start without one."""

SERVED_VARIANTS = ("phys-nn+", "phys-q")
"""The variants with coefficients inside the equations of motion: exported as bundles the service flies."""

NN_NOT_SERVED = ("--variant nn predicts landing points only (no coefficients for the service to fly, no height, no "
                 "path): it is trained and evaluated, never exported as a bundle; leave out --out")


@dataclass(frozen=True)
class Start:
    """A variant's starting network: `bundle` (a bundle directory) or, where None, the variant's own start
    (Ferguson 2022 for Phys-Q, a fresh network for NN). Picklable, so each seed's process builds its own copy."""

    variant: str = "phys-nn+"
    bundle: str | None = DEFAULT_INIT["phys-nn+"]

    def __post_init__(self) -> None:
        if self.variant not in REAL_VARIANTS:
            raise InputError(f"--variant must be one of {list(REAL_VARIANTS)}, got {self.variant!r}")
        if self.variant == "nn" and self.bundle is not None:
            raise InputError("--variant nn starts from a fresh network (paper eq. 23): it takes no --init bundle")
        if self.variant == "phys-nn+" and self.bundle is None:
            raise InputError("--variant phys-nn+ needs an --init bundle to start from (default models/synthetic)")

    def network(self) -> nn.Module:
        """A fresh copy of the starting network. A bundle of another variant is refused, naming both."""
        from golfflight.model_export.bundle_model import model_from_bundle
        from golfflight.model_export.variants import build_model

        if self.bundle is None:
            return build_model(self.variant, DEFAULT_HIDDEN)
        model, card = model_from_bundle(self.bundle)
        if card.variant != self.variant:
            raise InputError(f"--init {self.bundle} is a {card.variant} bundle; --variant {self.variant} needs a "
                             f"{self.variant} bundle (or none: Phys-Q then starts from Ferguson 2022)")
        return model


def start_of(variant: str, init: str | os.PathLike | None) -> Start:
    """The Start of `variant` from the command line's `--init` (None: the variant's default)."""
    bundle = DEFAULT_INIT.get(variant) if init is None else str(init)
    return Start(variant, bundle)
