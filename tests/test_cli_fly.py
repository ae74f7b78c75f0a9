"""`golfflight fly` as a golfer uses it (issue 23, item 5): the served model by default (the same numbers as POST
/v1/shots), launch-monitor units beside SI, out-of-range values refused with the API's message (exit 2, one line, no
warnings), and one club-name table with aliases shared by the CLI and the viewer."""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from golfflight.contract.clubs import CLUB_ALIASES, FLIES_AS, GSPRO_CLUBS, club_code, club_key
from golfflight.contract.inputs import air_of
from golfflight.flight.bundle_location import model_dir
from golfflight.flight.constants import MPH_TO_MPS
from golfflight.flight.engine import FlightEngine, Launch
from golfflight.flight.flyer import Flyer
from golfflight.flight.physics import initial_state
from golfflight.flight.problem import FlightProblem
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from golfflight.service.viewer.page import ASSETS
from golfflight.shots import reference_world
from golfflight.shots.clubs import CLUB_NAMES, CLUBS
from golfflight.shots.reference_world import fly_reference

from golfflight.cli import main
from golfflight.commands.fly import club_named
from tests.servers import running

REPO = Path(__file__).resolve().parents[1]


def fly_json(capsys, *argv: str) -> dict:
    assert main(["fly", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.fixture(scope="module")
def api():
    with running(create_app(ServiceSettings())) as http:
        yield http


def test_fly_flies_the_served_model_as_post_v1_shots_does(api, capsys):
    out = fly_json(capsys, "--club", "Driver")
    driver = next(c for c in CLUBS if c.name == "Driver")
    launch = Launch(driver.ball_speed_mps, driver.launch_angle_deg, 0.0, driver.spin_rpm, 0.0)
    engine = FlightEngine(model_dir())
    assert out["club"] == "Driver" and out["model"]["sha256"] == engine.sha256
    assert out["flight"]["carry_m"] == pytest.approx(engine.fly(FlightProblem.of([launch]))[0].carry_m, abs=1e-9)
    served = api.post("/v1/shots", json=out["request"])
    assert served.status_code == 200
    answered = served.json()
    flown_in = answered.pop("flown_in")  # the service says what it flew in; the command line flies in no bay
    assert out["flight"] == answered  # every other field of the API's result, the same numbers
    assert {flown_in[f"{name}_from"] for name in ("air", "wind", "ground")} == {"default"}
    for field in ("carry_m", "carry_yd", "total_m", "total_yd", "apex_m", "apex_yd", "lateral_m", "landing_angle_deg"):
        assert field in out["flight"], field

    table = (main(["fly", "--club", "dr"]), capsys.readouterr().out)
    assert table[0] == 0 and f"{out['flight']['carry_yd']:8.1f} yd" in table[1] and "total" in table[1]


def test_fly_model_chooses_the_bundle_and_reference_flies_the_reference_world(capsys):
    served = fly_json(capsys, "--club", "7i")["flight"]["carry_m"]
    other = fly_json(capsys, "--club", "7i", "--model", str(REPO / "models" / "synthetic"))
    assert other["model"]["bundle"].endswith("synthetic") and other["flight"]["carry_m"] != served

    reference = fly_json(capsys, "--club", "7i", "--reference")
    assert reference["model"] == {"world": "reference"}
    seven = club_named("7-iron")
    state = initial_state(*(np.array([v], dtype=float) for v in Launch(seven.ball_speed_mps, seven.launch_angle_deg,
                                                                       0.0, seven.spin_rpm, 0.0)))
    flight = fly_reference(state, air_of(None))  # the API's default: ICAO standard air
    assert reference["flight"]["carry_m"] == pytest.approx(float(flight.carry_m[0]), abs=1e-9)
    assert reference["flight"]["total_m"] > reference["flight"]["carry_m"] - 10.0 and "bounces" in reference["flight"]


def test_launch_monitor_units_fly_the_same_shot_as_si(capsys):
    si = fly_json(capsys, "--ball-speed-mps", str(150 * MPH_TO_MPS), "--launch-angle-deg", "12", "--spin-rpm", "3000",
                  "--wind-speed-mps", str(10 * MPH_TO_MPS), "--wind-from-deg", "90")
    mph = fly_json(capsys, "--ball-speed-mph", "150", "--launch-angle-deg", "12", "--back-spin-rpm", "3000",
                   "--wind-speed-mph", "10", "--wind-from-deg", "90")
    assert mph["request"]["ball_speed_mph"] == 150.0 and "ball_speed_mps" not in mph["request"]
    for field in ("carry_m", "total_m", "apex_m", "lateral_m", "landing_angle_deg"):
        assert mph["flight"][field] == pytest.approx(si["flight"][field], abs=1e-6), field
    assert si["flight"]["lateral_m"] < -1.0  # the wind from the right moves it left


def _api_message(api, field: str, value: float, base: dict) -> str:
    """The API's 422 message for a request with `field` (dotted: wind.speed_mps) set to `value`, without its
    field prefix."""
    body = json.loads(json.dumps(base))
    *parents, name = field.split(".")
    target = body
    for parent in parents:
        target = target.setdefault(parent, {})
    target[name] = value
    answer = api.post("/v1/shots", content=json.dumps(body), headers={"content-type": "application/json"})
    assert answer.status_code == 422, answer.text
    detail = answer.json()["detail"][0]
    assert detail["field"] == field
    return detail["message"].removeprefix(f"{field}:")


@pytest.mark.parametrize(
    "flag, value, field",
    [
        ("--ball-speed-mps", 200.0, "ball_speed_mps"),
        ("--ball-speed-mps", -5.0, "ball_speed_mps"),
        ("--ball-speed-mph", 300.0, "ball_speed_mph"),
        ("--launch-angle-deg", 95.0, "launch_angle_deg"),
        ("--spin-rpm", 20000.0, "spin_rpm"),
        ("--altitude-m", 9000.0, "air.altitude_m"),
        ("--temperature-c", -80.0, "air.temperature_c"),
        ("--wind-speed-mps", 45.0, "wind.speed_mps"),
        ("--wind-from-deg", 400.0, "wind.from_deg"),
        ("--launch-angle-deg", float("nan"), "launch_angle_deg"),
    ],
)
def test_out_of_range_values_are_refused_with_the_api_message(api, capsys, flag, value, field):
    base = {"ball_speed_mps": 55.0, "launch_angle_deg": 16.0, "spin_rpm": 7100.0}
    if field.startswith("wind.") and field != "wind.speed_mps":
        base["wind"] = {"speed_mps": 0.0}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(["fly", "--club", "7i", flag, str(value)]) == 2
    captured = capsys.readouterr()
    assert caught == [] and captured.out == "" and "Traceback" not in captured.err
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0] == f"golfflight fly: error: {flag}:{_api_message(api, field, value, base)}"
    assert "allowed" in lines[0]


def test_mph_wind_out_of_range_and_both_units_are_refused(capsys):
    assert main(["fly", "--wind-speed-mph", "100"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("golfflight fly: error: --wind-speed-mph: ") and "allowed 0 to 67.1 mph" in err
    for argv in (
        ["--ball-speed-mps", "60", "--ball-speed-mph", "130"],
        ["--wind-speed-mps", "3", "--wind-speed-mph", "7"],
        ["--spin-rpm", "3000", "--back-spin-rpm", "3000"],
    ):
        assert main(["fly", *argv]) == 2
        err = capsys.readouterr().err
        assert len(err.splitlines()) == 1 and "not both" in err and argv[0] in err and argv[2] in err, err
    assert main(["fly", "--spin-axis-deg", "3", "--side-spin-rpm", "400"]) == 2
    assert "--spin-axis-deg goes with --spin-rpm" in capsys.readouterr().err


def test_a_reference_shot_the_world_cannot_bring_down_is_refused_in_one_line(monkeypatch, capsys):
    world = reference_world.reference_flyer()
    short = Flyer(world.model, world.dt_s, 1.0, world.density_kg_m3, world.kinematic_viscosity_m2_s, world.rule)
    monkeypatch.setattr(reference_world, "reference_flyer", lambda: short)
    assert main(["fly", "--club", "Driver", "--reference"]) == 2
    err = capsys.readouterr().err
    assert err.splitlines() == [
        "golfflight fly: error: the reference world could not fly the shot: the ball was still in the air after 1 s "
        "(the simulation cap)"
    ]


@pytest.mark.parametrize("typed", ["7i", "7 iron", "7-Iron", "7-iron", "7IRON", "i7", " 7 Iron ", "I7"])
def test_what_a_golfer_types_names_the_canonical_club(typed):
    assert club_code(typed) == "I7"
    assert club_named(typed) == next(c for c in CLUBS if c.name == "7-iron")


def test_the_alias_table_covers_every_club_and_refuses_unknown_names(capsys):
    assert CLUB_NAMES == tuple(c.name for c in CLUBS)
    assert set(CLUB_ALIASES.values()) == set(GSPRO_CLUBS) and set(FLIES_AS) == set(GSPRO_CLUBS)
    assert {name for name in FLIES_AS.values() if name} == set(CLUB_NAMES)
    for name in CLUB_NAMES:
        assert club_named(name).name == name and club_named(name.lower()).name == name
    for typed, name in {"dr": "Driver", "DRIVER": "Driver", "3w": "3-wood", "W5": "5-wood", "hy": "Hybrid",
                        "pw": "PW", "Gap Wedge": "GW", "sw": "SW", "lob wedge": "LW", "9i": "9-iron"}.items():
        assert club_named(typed).name == name, typed
    assert all(club_key(alias) == alias for alias in CLUB_ALIASES)
    for unknown in ("", "10i", "8w", "wedge"):
        with pytest.raises(ValueError) as error:
            club_named(unknown)
        assert "unknown club" in str(error.value) and all(code in str(error.value) for code in GSPRO_CLUBS)
    assert main(["fly", "--club", "putter"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "putter has no tour-average launch" in err and "7-iron" in err


def test_the_viewer_offers_gspros_clubs_by_their_codes():
    page = ASSETS["viewer.html"][0].decode()
    menu = page[page.index('<select id="club">') : page.index("</select>", page.index('<select id="club">'))]
    offered = [part.split('"', 1)[0] for part in menu.split('<option value="')[1:]]
    assert offered == list(GSPRO_CLUBS) and all(name in menu for name in GSPRO_CLUBS.values())
    assert "<!--" not in menu


def test_every_gspro_club_code_but_the_putter_names_a_club_to_fly():
    """Issue 43: `fly --club H4` was refused though the bay takes GSPro's codes; each now flies as the nearest club
    with a launch of its own, and the putter still says what it takes."""
    assert {club_named(code).name for code in GSPRO_CLUBS if code != "PT"} <= set(CLUB_NAMES)
    assert club_named("H4").name == "Hybrid" and club_named("w2").name == "3-wood"
    with pytest.raises(ValueError, match="'PT': the putter has no tour-average launch"):
        club_named("PT")
