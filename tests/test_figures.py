"""Results defined once (issue 24): every figure of a flight's outcome is one `contract.figures.Figure`, from which
the HTTP result models, the simulate/sweep columns and `golfflight fly`'s table are derived; a field added to the
engine's outcome record without a figure fails here, named."""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

import pytest
from golfflight.contract.columns import PASSED_OVER, result_columns
from golfflight.contract.figures import (
    FIGURES,
    FLAT_FIGURES,
    NOT_FIGURES,
    flight_numbers,
    outcome_fields,
    unreported_fields,
)
from golfflight.contract.results import POINT_MODELS, FlatFlight, FlightResult
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.constants import YARD_M
from golfflight.flight.engine import BatchFlights, FlightEngine, Launch, Rest, ShotFlight
from golfflight.flight.ground import LEVEL_FAIRWAY
from golfflight.flight.problem import FlightProblem

from golfflight.cli import main

CONTRACT = Path(__file__).resolve().parents[1] / "contract"


@dataclass(frozen=True)
class RestWithSkid(Rest):
    """A rest that has gained a figure the contract does not know yet."""

    skid_m: float = 0.0


@dataclass(frozen=True)
class FlightWithSpinDecay(ShotFlight):
    """An outcome record that has gained a figure of its own and one in its rest."""

    spin_decay_rpm: float = 0.0
    rest: RestWithSkid | None = None


@pytest.mark.parametrize("record", [ShotFlight, BatchFlights])
def test_every_field_of_the_outcome_records_is_a_figure_or_said_to_be_none(record):
    assert unreported_fields(record) == []
    assert {figure.record_field for figure in FIGURES} <= set(outcome_fields(record)), "a figure reads a field gone"


def test_every_field_said_to_be_no_figure_is_a_field_of_an_outcome_record():
    assert set(NOT_FIGURES) <= set(outcome_fields(ShotFlight)) | set(outcome_fields(BatchFlights))


def test_a_field_added_to_the_outcome_record_without_a_figure_is_named():
    assert unreported_fields(FlightWithSpinDecay) == ["rest.skid_m", "spin_decay_rpm"]


def test_every_figure_is_a_field_of_the_http_result_a_column_and_a_row_of_the_fly_table(capsys):
    fields = FlightResult.model_fields
    columns = result_columns(normalized=False, flat=False)
    for figure in FIGURES:
        names = [name for name in (figure.name, figure.twin) if name]
        assert all(name in columns for name in names), figure.name
        if figure.point is None:
            assert all(name in fields for name in names) and fields[figure.name].description == figure.description
        else:
            point = POINT_MODELS[figure.point.name]
            assert fields[figure.point.name].annotation is point
            assert point.model_fields[figure.coordinate].description == figure.description
    flat = [figure.name for figure in FLAT_FIGURES if figure.point is None]
    assert [name for name in FlatFlight.model_fields if not name.endswith("_yd")] == ["landing", *flat]

    assert main(["fly", "--club", "7i"]) == 0
    table = capsys.readouterr().out.splitlines()[1:]
    assert [row.split("  ")[1].strip() for row in table] == [f.label for f in FIGURES if f.point is None]


def test_the_numbers_of_a_flight_are_its_figures_with_their_twins():
    seven_iron = FlightProblem.of([Launch(55.0, 16.0, 0.0, 7100.0, 0.0)], grounds=LEVEL_FAIRWAY)
    flight = FlightEngine(model_dir()).fly(seven_iron)[0]
    numbers = flight_numbers(flight)
    assert list(numbers) == [name for figure in FIGURES for name in (figure.name, figure.twin) if name]
    assert numbers["carry_m"] == flight.carry_m and numbers["total_m"] == flight.rest.total_m
    assert numbers["carry_yd"] == pytest.approx(flight.carry_m / YARD_M, rel=1e-15)
    assert numbers["bounces"] == flight.rest.bounces and isinstance(numbers["bounces"], int)


def test_no_contract_module_but_the_figures_names_a_figure():
    """The contract lists the figures once: a figure's name written out anywhere else in contract/ is a second list
    (the canonical shot files' observed columns that `golfflight simulate` passes over are input, not results)."""
    names = {name for figure in FIGURES for name in (figure.name, figure.twin) if name}
    offenders = []
    for path in sorted(CONTRACT.glob("*.py")):
        if path.name == "figures.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Constant) and node.value in names and node.value not in PASSED_OVER:
                offenders.append(f"{path.name}:{node.lineno}: {node.value!r}")
    assert offenders == []
