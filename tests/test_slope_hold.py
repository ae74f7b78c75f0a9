"""The steepest slope a surface holds a ball still on is checked by one function (`flight.ground.check_slope_held`):
a shot's ground, the ground phase (a batch and one ball), a putt and a request over HTTP refuse the same slope on the
same green with the same words, naming slope_deg, the holding slope and the range allowed."""

from __future__ import annotations

import numpy as np
import pytest
from golfflight.errors import InputError
from golfflight.flight.ground import GroundSpec, ground_phase, ground_phase_one, holding_slope_deg, putt_phase, surface
from golfflight.service.app import create_app
from servers import running

GREEN = surface("green", 11.0)
"""A stimp-11 green: it holds a ball on slopes below atan(7/5 c_r), about 4.07 degrees."""

STEEP_DEG = 6.0

LANDING = ((0.0, 0.0, 0.0), (1.0, 20.0, -15.0), (300.0, 0.0, 0.0))
"""A wedge's landing (position, velocity, spin in rad/s) on floats."""


def _refusal(call) -> str:
    with pytest.raises(InputError) as refused:
        call()
    return str(refused.value)


def test_every_place_that_takes_a_slope_refuses_a_steep_one_in_the_same_words():
    batch = [np.array([value] * 2) for value in LANDING]
    messages = {
        "GroundSpec": _refusal(lambda: GroundSpec(GREEN, slope_deg=STEEP_DEG)),
        "ground_phase": _refusal(lambda: ground_phase(*batch, GREEN, np.array([1.0, STEEP_DEG]))),
        "ground_phase_one": _refusal(lambda: ground_phase_one(*LANDING, GREEN, STEEP_DEG)),
        "putt_phase": _refusal(lambda: putt_phase(1.83, 2.0, 0.0, 0.0, 0.0, GREEN, STEEP_DEG)),
    }
    assert len(set(messages.values())) == 1, messages
    limit = float(holding_slope_deg(GREEN.rolling_resistance))
    message = messages["GroundSpec"]
    assert message.startswith("slope_deg: 6 is steeper") and f"({limit:.2f} deg" in message
    assert f"allowed 0 to {limit - 0.005:.2f} deg" in message
    with running(create_app()) as http:
        answer = http.post("/v1/shots", json={"ball_speed_mps": 30.0, "launch_angle_deg": 30.0, "spin_rpm": 8000.0,
                                              "ground": {"surface": "green", "stimp_ft": 11.0, "slope_deg": STEEP_DEG}})
    assert answer.status_code == 422, answer.text
    assert message.replace("the surface", "green") in answer.json()["detail"][0]["message"]
