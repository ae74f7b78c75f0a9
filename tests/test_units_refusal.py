"""Issue 56, item 10: a connector's unknown `Units` is refused in one plain sentence, over HTTP (POST /v1/gspro) and
over Open Connect TCP alike: the field named once, the allowed values, and what was sent quoted once (the message said
"Units: Units must be ... got 'Metres' (got 'Metres')")."""

from __future__ import annotations

import json

from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from servers import free_port, running
from test_viewer import WEDGE_BALL, reply_over_tcp

METRES = {"ShotNumber": 1, "APIversion": "1", "Units": "Metres", "BallData": WEDGE_BALL}
"""A shot in British spelling: GSPro's value is "Meters"."""


def _said_once(message: str) -> None:
    assert message.count("Metres") == 1 and message.count("Units") == 1, message
    assert "Units: must be Yards or Meters" in message and "(got 'Metres')" in message, message


def test_an_unknown_units_is_refused_naming_the_field_and_the_value_once_over_http_and_tcp():
    port = free_port()
    with running(create_app(ServiceSettings(connect_port=port))) as http:
        over_http = http.post("/v1/gspro", json=METRES).json()
        over_tcp = reply_over_tcp(port, json.dumps(METRES).encode())
    for reply in (over_http, over_tcp):
        assert reply["Code"] == 500, reply
        _said_once(reply["Message"])
