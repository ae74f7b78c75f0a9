"""Training side of Phys-NN+: differentiable PyTorch physics, model variants, training loop and ONNX export.

The submodules need the `train` extra (torch, onnx, tqdm). This file stays torch-free so the command line
can list the variants in an install without torch.
"""

PHYS_NN_VARIANTS = ("phys-nn", "phys-nn-pm", "phys-nn-pm-cq", "phys-nn+")
"""Table 1's MLP variants; phys-nn+ (the paper's final model, trained on L_p + L_h) has phys-nn-pm-cq's architecture."""

PHYSICS_VARIANTS = (*PHYS_NN_VARIANTS, "phys-q")
"""Variants with a coefficient model inside the equations of motion: the exportable ones."""

VARIANTS = (*PHYSICS_VARIANTS, "nn")
"""All variants, with the NN baseline (launch -> landing point, no physics)."""

DEFAULT_HIDDEN = (256, 128)
