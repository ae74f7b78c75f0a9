"""The fine-tuning study of `golfflight accuracy`: `golfflight finetune` on some rounds of a tour event, measured on
the event's later rounds before and after. It never touches a held-out set (`shots.heldout`): the event is the Sony
Open 2022 (trajectories only, so its spin is the loader's estimate from the initial lift). The fine-tuning itself
(`model_export.finetune.finetune`, torch) is passed in by the caller, so this package needs no torch.
"""

from __future__ import annotations

import os
import re
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from golfflight.contract.problems import launch_problem
from golfflight.errors import InputError
from golfflight.evaluation.accuracy_flyers import model_flyer
from golfflight.evaluation.accuracy_sets import ClubComparison, compare_clubs, outcome_errors
from golfflight.flight.flyer import Flyer
from golfflight.shots.progress import progress_bar
from golfflight.shots.records import ShotSet, write_shots
from golfflight.shots.reference_world import ClubAverage
from golfflight.shots.source_air import PGA_2023_TABLE

TRAIN_ROUNDS = (1, 2)
MEASURED_ROUNDS = (3, 4)
ROUND = re.compile(r"-R(\d+)(?:-|$)")


def round_number(session: str | None, shot_id: str | None) -> int | None:
    """The round of a TOURCAST shot: from its session ('006-R2') or its id ('006-R2-H5-P1-S1')."""
    for text in (session, shot_id):
        match = ROUND.search(text or "")
        if match:
            return int(match.group(1))
    return None


def by_rounds(shots: ShotSet, rounds: Sequence[int]) -> ShotSet:
    return ShotSet([r for r in shots.records if round_number(r.session, r.shot_id) in rounds])


class Finetune(Protocol):
    """`model_export.finetune.finetune` as the study calls it: fine-tune a bundle on a canonical file and export the
    best epoch to `out` if it beats the base model; the result has `run` (best, data), `improved`, `base_metrics`."""

    def __call__(self, model: str | os.PathLike, data: str | os.PathLike, out: str | os.PathLike, epochs: int,
                 lr: float, batch_size: int, *, val_fraction: float, progress: bool) -> Any: ...


@dataclass
class FinetuneStudy:
    """The later rounds before and after fine-tuning on the earlier ones, and what it did to the PGA table.
    `validation` holds, per learning rate tried, the best epoch's validation landing error (m) and that epoch."""

    n_shots: int
    n_train: int
    n_val: int
    n_measured: int
    epochs: int
    lr: float
    batch_size: int
    best_epoch: int | None
    improved: bool
    before: dict[str, np.ndarray]
    after: dict[str, np.ndarray]
    base_validation_m: float
    validation: dict[float, tuple[float, int | None]]
    pga_after: ClubComparison | None = None


def finetune_study(
    flyer: Flyer,
    shots: ShotSet,
    clubs: Sequence[ClubAverage] | None,
    finetune: Finetune,
    epochs: int = 30,
    lrs: Sequence[float] = (3e-4, 1e-3),
    batch_size: int = 64,
    val_fraction: float = 0.2,
    train_rounds: Sequence[int] = TRAIN_ROUNDS,
    measured_rounds: Sequence[int] = MEASURED_ROUNDS,
    progress: bool = False,
) -> FinetuneStudy:
    """Fine-tune on `train_rounds` at each learning rate (written without a split column, so `golfflight finetune`
    picks its validation shots by its own rule: the latest sessions, i.e. rounds), keep the rate whose best epoch has
    the lowest validation landing error (the measured rounds play no part in any choice), and compare
    `measured_rounds` before and after. Everything is written to a temporary directory, then deleted. With `progress`,
    a bar over the learning rates goes to standard error (the runs' own lines would go to standard output)."""
    train, measured = by_rounds(shots, train_rounds), by_rounds(shots, measured_rounds)
    if not len(train) or not len(measured):
        raise InputError(f"needs shots in rounds {list(train_rounds)} and {list(measured_rounds)}; "
                         f"found {len(train)} and {len(measured)}")
    launch = measured.launch()
    before = outcome_errors(flyer.flight(launch_problem(launch)), measured)
    with tempfile.TemporaryDirectory(prefix="golfflight-finetune-") as work:
        train_file = Path(work) / "train_rounds.csv"
        write_shots(train_file, [r.model_copy(update={"split": None}) for r in train.records])
        results = {}
        for index, lr in enumerate(progress_bar(lrs, "fine-tuning, learning rates", unit="rate", shown=progress)):
            out = Path(work) / f"bundle-{index}"
            results[lr] = (out, finetune(flyer.bundle_dir, train_file, out, epochs, lr, batch_size,
                                         val_fraction=val_fraction, progress=False))
        validation = {lr: (float(r.run.best["landing_error_m"]) if r.run.best else float("inf"),
                           None if r.run.best is None else int(r.run.best["epoch"])) for lr, (_, r) in results.items()}
        lr = min(validation, key=lambda rate: validation[rate][0])
        out, result = results[lr]
        tuned = model_flyer(out) if result.improved else flyer
        after = outcome_errors(tuned.flight(launch_problem(launch)), measured)
        pga_after = compare_clubs(tuned, clubs, PGA_2023_TABLE.air()) if clubs and result.improved else None
    return FinetuneStudy(
        n_shots=len(shots),
        n_train=result.run.data.n_train,
        n_val=result.run.data.n_val,
        n_measured=len(measured),
        epochs=epochs,
        lr=lr,
        batch_size=batch_size,
        best_epoch=validation[lr][1],
        improved=result.improved,
        before=before,
        after=after,
        base_validation_m=float(result.base_metrics["landing_error_m"]),
        validation=validation,
        pga_after=pga_after,
    )
