"""Each source's share of the session memory (issue 55, item 9): the shot cap used to let the oldest shot of all go
first, so one connector's flood (8 connections at 600 shots a second) emptied an older session of another's shots.
Now the source holding the most lets its own oldest go. The whole service on loopback: a connector on 127.0.0.2
and HTTP shots from 127.0.0.1 play a session, then a flood from 127.0.0.1 on 8 Open Connect connections sends three
times the cap (here 120 shots: the same rule as the shipped 10,000, met in a second instead of half a minute)."""

from __future__ import annotations

import json
import socket
from concurrent.futures import ThreadPoolExecutor

from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings

from tests.servers import free_port, running
from tests.test_open_connect import encoded, shot

CAP = 120
DRIVER = {"ball_speed_mph": 167.0, "launch_angle_deg": 10.9, "back_spin_rpm": 2686.0, "side_spin_rpm": -250.0}
FLOOD_CONNECTIONS = 8


def played(port: int, source: str, numbers: range) -> None:
    """A connector from `source` sending shots `numbers` on one connection, each answered Code 200 before the next."""
    with socket.socket() as sock:
        sock.bind((source, 0))
        sock.connect(("127.0.0.1", port))
        sock.settimeout(10)
        for number in numbers:
            sock.sendall(encoded(shot(number)))
            reply = json.loads(sock.recv(65536))
            assert reply["Code"] == 200 and reply["ShotNumber"] == number, reply


def test_a_flood_from_one_address_pushes_out_only_its_own_shots():
    port = free_port()
    app = create_app(ServiceSettings(connect_port=port))
    with running(app) as http:
        app.state.runtime._feed.sessions.max_shots = CAP
        played(port, "127.0.0.2", range(1, 31))  # session 1: a connector's 30 shots, and 5 over HTTP
        for _ in range(5):
            assert http.post("/v1/shots?viewer=1", json=DRIVER).status_code == 200
        assert http.post("/v1/sessions", json={"player": "next"}).status_code == 201
        per_connection = 3 * CAP // FLOOD_CONNECTIONS
        with ThreadPoolExecutor(FLOOD_CONNECTIONS) as pool:  # session 2: the flood, three times the cap
            starts = range(1000, 1000 + FLOOD_CONNECTIONS * per_connection, per_connection)
            list(pool.map(lambda first: played(port, "127.0.0.1", range(first, first + per_connection)), starts))
        first, second = http.get("/v1/sessions").json()["sessions"]
    assert (first["shots"], first["dropped_shots"]) == (35, 0), first  # the connector's and HTTP's, all kept
    assert (second["shots"], second["dropped_shots"]) == (CAP - 35, 3 * CAP - (CAP - 35)), second
