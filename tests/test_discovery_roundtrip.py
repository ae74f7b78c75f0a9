"""The round trip of issue 14: the corrected settings `golfflight diagnose` writes, sent to the service in its own
request fields, reproduce held-out recordings with the improvement the report claims."""

from __future__ import annotations

import json

import numpy as np
import pytest
from golfflight.contract.inputs import conditions_of
from golfflight.contract.requests import ShotRequest
from golfflight.discovery.conceal import conceal
from golfflight.discovery.model import load_model
from golfflight.discovery.schema import Report
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.problem import FlightProblem
from golfflight.shots.records import LAUNCH_COLUMNS, write_shots

from golfflight.cli import main

WIND = {"wind": {"speed_mps": 4.0, "from_deg": 230.0}}


def _service_rms(engine: FlightEngine, records, settings: dict | None) -> np.ndarray:
    """RMS (along, across) in metres of recorded minus served landings, with the settings' wind or without."""
    launches, conditions = [], []
    for record in records:
        launch = {name: getattr(record, name) for name in LAUNCH_COLUMNS}
        request = ShotRequest.model_validate({**launch, **({"wind": settings["wind"]} if settings else {})})
        launches.append(Launch(*launch.values()))
        conditions.append(conditions_of(request))
    flights = engine.fly_batch(FlightProblem.of(launches, conditions=conditions)).shots()
    residual = np.array([[r.carry_y_m - f.landing_y_m, r.carry_x_m - f.landing_x_m] for r, f in zip(records, flights)])
    return np.sqrt(np.mean(residual**2, axis=0))


def test_the_written_settings_reproduce_held_out_recordings_in_the_service(tmp_path):
    served = load_model(None)
    recorded = tmp_path / "recorded.csv"
    write_shots(recorded, conceal(WIND, 200, seed=51, model=served).shots.records)
    assert main(["diagnose", str(recorded), "--out", str(tmp_path)]) == 0
    report = Report.model_validate_json((tmp_path / "report.json").read_text())
    settings = json.loads((tmp_path / "service_settings.json").read_text())
    assert [e.name for e in report.effects] == ["wind"] and settings["wind"]["profile"] == "uniform"

    held_out = conceal(WIND, 200, seed=52, model=served).shots.records  # other sessions, launches and noise
    engine = FlightEngine(model_dir())
    before, after = _service_rms(engine, held_out, None), _service_rms(engine, held_out, settings)
    claimed_before = np.array([report.heldout.before[name] for name in ("carry_y_m", "carry_x_m")])
    claimed_after = np.array([report.heldout.after[name] for name in ("carry_y_m", "carry_x_m")])
    assert after == pytest.approx(claimed_after, rel=0.3), "the service lands where the report says it will"
    assert after / before == pytest.approx(claimed_after / claimed_before, abs=0.1)
    assert np.all(after < 0.5 * before)
