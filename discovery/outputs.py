"""Write a diagnosis to its output folder: report.json, report.html and service_settings.json."""

from __future__ import annotations

import os
from pathlib import Path

from golfflight.discovery.html import render
from golfflight.shots.files import write_text_atomic


def write_diagnosis(diagnosis, out: str | os.PathLike) -> list[Path]:
    """The three output files of `golfflight diagnose`, in `out`."""
    out = Path(out)
    paths = [out / "report.json", out / "report.html", out / "service_settings.json"]
    write_text_atomic(paths[0], diagnosis.report.model_dump_json(indent=2) + "\n")
    write_text_atomic(paths[1], render(diagnosis))
    write_text_atomic(paths[2], diagnosis.report.service_settings.model_dump_json(indent=2, exclude_none=True) + "\n")
    return paths
