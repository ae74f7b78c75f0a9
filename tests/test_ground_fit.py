"""The fairway fit (`golfflight ground-fit`): the table's fairway row is the committed fit, the fit's pieces work on
the pbp fixture (its first lines: one radar tee shot at rest on the fairway), and on the real data (skipped when
absent) the committed error is what the code gives."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from golfflight.flight.flyer import load_flyer
from golfflight.flight.ground import SURFACES
from golfflight.shots.ground_fit import FAIRWAY_LIES, FIT_EVENT, FITTED, fairway_shots, landings, score, totals
from golfflight.shots.paths import REPO_ROOT, shared_data_dir

RESULTS = REPO_ROOT / "docs" / "ground_fit.json"
FIXTURE = Path(__file__).parent / "fixtures" / "pbp.csv"


def test_the_fairway_row_is_the_committed_fit():
    fitted = json.loads(RESULTS.read_text())["fairway"]
    for name in FITTED:
        assert getattr(SURFACES["fairway"], name) == pytest.approx(fitted[name], rel=1e-3, abs=1e-4), name


def test_docs_name_the_model_the_numbers_were_made_with():
    sha = json.loads(RESULTS.read_text())["model_sha256"]
    assert f"ONNX SHA-256 `{sha}`" in (REPO_ROOT / "docs" / "ground.md").read_text()


def test_fairway_rests_of_the_fixture_fly_land_and_roll_on(tmp_path):
    path = tmp_path / "pbp.csv"
    path.write_text("".join(FIXTURE.read_text().splitlines(keepends=True)[:4]))
    shots = fairway_shots("fixture", path)
    assert len(shots.launches) == 1
    flight = landings(shots, load_flyer())
    assert flight.landed.all()
    np.testing.assert_allclose(flight.landing_position[:, 2], shots.rest_dz_m, atol=1e-9)
    assert np.all(totals(flight, SURFACES["fairway"]) > flight.carry_m)


def test_a_constant_roll_scores_its_own_median_as_zero_bias():
    carry, distance = np.array([200.0, 210.0, 220.0]), np.array([212.0, 219.0, 235.0])
    result = score("e", "constant", carry + 12.0, carry, distance)
    assert result.bias_m == 0.0 and result.mae_m == pytest.approx(2.0) and result.median_roll_m == 12.0


def test_the_committed_fit_error_is_what_the_code_gives():
    name, relative = FIT_EVENT
    path = shared_data_dir() / relative
    if not path.exists():
        pytest.skip(f"{path} is not here")
    results = json.loads(RESULTS.read_text())
    flyer = load_flyer()
    if flyer.card.onnx.sha256 != results["model_sha256"]:
        pytest.skip("models/default changed since docs/ground_fit.json: re-run `golfflight ground-fit`")
    shots = fairway_shots(name, path)
    assert len(shots.launches) > 1000
    error = np.mean(np.abs(totals(landings(shots, flyer), SURFACES["fairway"]) - shots.distance_m))
    assert error == pytest.approx(results["fit_mae_m"], abs=0.02)
    assert set(FAIRWAY_LIES) == {"ELF", "ERF"}
