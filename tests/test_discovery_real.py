"""`python -m discovery.real` on a real set: the shared data are read in place, and the summary row says how the
recordings scatter and what was found (skipped where ../shared/data is absent)."""

from __future__ import annotations

import json

import pytest

from discovery.real import TRACKMAN, main
from shots.paths import shared_data_dir


def test_real_run_writes_a_summary_row_and_a_report(tmp_path):
    if not (shared_data_dir() / TRACKMAN).is_file():
        pytest.skip("needs the shared real data")
    assert main(["--out", str(tmp_path), "--model", "reference", "--only", "pga_2023_averages$"]) == 0
    summary = (tmp_path / "summary.md").read_text().splitlines()
    assert "scatter (x assumed noise)" in summary[2] and len(summary) == 5
    assert "PGA TOUR 2023 averages" in summary[4]
    details = json.loads((tmp_path / "details.json").read_text())
    assert set(details) == {"pga_2023_averages"} and details["pga_2023_averages"]["statement"]
    assert (tmp_path / "pga_2023_averages" / "report.json").is_file()
