"""The choices the discovery commands offer (`golfflight diagnose --model`, `golfflight prove --truth --campaign
--clean-sets`), apart from the code that acts on them, so that a command's help lists them without importing it."""

from __future__ import annotations

from typing import Literal

REFERENCE = "reference"
"""`--model reference` diagnoses against the reference world instead of a bundle."""

CLEAN_SETS = 40
"""Clean sets per campaign, whatever the seeds per case: false alarms are counted on at least this many."""
SHOTS = 300
"""Shots per concealed set (and per baseline session), unless a campaign is told otherwise."""

Truth = Literal["model", "reference", "ferguson", "density-only", "density-only-rk4"]
TRUTHS: tuple[Truth, ...] = ("model", "reference", "ferguson", "density-only", "density-only-rk4")
"""The worlds effects are hidden in: the diagnosed model's own flights, and those that differ from it in form (the
model-form campaign): the reference world, Ferguson 2022's closed-form coefficients, and the model itself in venue
air that scales density only (recorded, so the model flies it with the Reynolds change real air has), as the service
flies it (forward Euler at the card's step) or by RK4 at 0.01 s (`density-only-rk4`: without the step error)."""

DENSITY_ONLY_WORLDS: tuple[Truth, ...] = ("density-only", "density-only-rk4")
"""The worlds whose venue air scales density only and is recorded with every shot."""

Campaign = Literal["library", "pairs", "triples", "baseline"]
CAMPAIGNS: tuple[Campaign, ...] = ("library", "pairs", "triples", "baseline")
"""The proof's campaigns: single library effects, pairs, triples, and against a baseline session."""
