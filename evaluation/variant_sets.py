"""The sets of the variant comparison (`variant_comparison`), each with its blocks: the held-out TrackMan drives
(Premium balls, and all balls; blocks: the range blocks `shots.range_blocks` draws, as training groups its lines),
the TOUR Championship's held-out rounds 3-4 (blocks: a hole of a round), and the validation split of the merged
real training file (blocks: its conditions groups), a set per source.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from golfflight.evaluation.accuracy_sets import (
    DRIVER_FILE,
    PREMIUM,
    TOUR_CHAMPIONSHIP_PBP,
    ball_types,
    held_out_driver_shots,
    tour_championship_shots,
)
from golfflight.evaluation.variant_comparison import ComparisonSet
from golfflight.shots.range_blocks import driver_groups
from golfflight.shots.records import read_shots
from golfflight.shots.source_air import TOUR_CHAMPIONSHIP_2020


def held_out_drives(data_dir: str | os.PathLike) -> list[ComparisonSet]:
    """The held-out TrackMan drives, Premium balls then all balls, flown in each model's own air (as
    `golfflight accuracy` flies them); none where the file is missing."""
    path = Path(data_dir) / DRIVER_FILE
    if not path.is_file():
        return []
    shots, _ = held_out_driver_shots(path)
    balls = ball_types(path)
    records = [r.model_copy(update={"ball": r.ball or balls.get(r.shot_id or "")}) for r in shots.records]
    blocks = np.array(driver_groups(records), dtype=object)
    premium = np.array([r.ball == PREMIUM for r in records])
    note = "TrackMan lines 2943 on, held out; each model in its own air"
    return [ComparisonSet("TrackMan drives, Premium balls (held out)", shots.subset(premium), blocks[premium], None,
                          note),
            ComparisonSet("TrackMan drives, all balls (held out)", shots, blocks, None, note)]


def tour_championship_apex(data_dir: str | os.PathLike) -> list[ComparisonSet]:
    """The TOUR Championship 2020's rounds 3-4 tee shots (apex only), in East Lake's air; blocks: round and hole."""
    path = Path(data_dir) / TOUR_CHAMPIONSHIP_PBP
    if not path.is_file():
        return []
    shots, _ = tour_championship_shots(path)
    blocks = np.array(["-".join(str(r.shot_id).split("-")[1:3]) for r in shots.records], dtype=object)
    return [ComparisonSet("TOUR Championship 2020 rounds 3-4, apex (held out)", shots, blocks,
                          TOUR_CHAMPIONSHIP_2020.air(), "every model in the event's air (`shots.source_air`)")]


def validation_sets(merged_file: str | os.PathLike) -> list[ComparisonSet]:
    """The merged training file's validation shots, a set per source, each flown calm in its recorded air; blocks:
    their conditions groups. Training never fitted these shots: they chose the epochs' runs, seeds and weights."""
    shots = read_shots(merged_file)
    val = shots.subset(shots.column("split") == "val")
    sets = []
    for source in dict.fromkeys(val.column("source")):
        mine = val.subset(val.column("source") == source)
        sets.append(ComparisonSet(f"{source}, validation split (training side)", mine,
                                  np.asarray(mine.column("group"), dtype=object), mine.air(),
                                  "calm, in the shots' recorded air"))
    return sets


def all_sets(data_dir: str | os.PathLike, merged_file: str | os.PathLike | None) -> list[ComparisonSet]:
    """Every held-out set found under `data_dir`, then the training side's validation sets of `merged_file`."""
    training = validation_sets(merged_file) if merged_file is not None else []
    return [*held_out_drives(data_dir), *tour_championship_apex(data_dir), *training]

