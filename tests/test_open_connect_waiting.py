"""Open Connect's places for a connector that connects and waits (issue 55, item 2): a real connector connects when
it starts and sends nothing until the golfer hits. Under a flood of sockets that never send a valid message,
connecting again whenever closed (a program in a process of its own), the connector that connected first keeps its
place however long it waits, and a connector that connects during the flood and sends its shot at once still gets
in; one that connects during a flood from another address keeps its place while it waits. Real TCP sockets on
loopback against a real `OpenConnectServer` (`Served`)."""

from __future__ import annotations

import socket
import subprocess
import sys
import time
from pathlib import Path

from golfflight.service.open_connect.limits import MAX_CONNECTIONS, WAITING_KEPT

from tests.test_open_connect_idle import EVICTED, close_all, held, new_connector_shot, played
from tests.test_open_connect_limits import Served, refusal, served, until_closed  # noqa: F401 (served: a fixture)

FLOOD_SOCKETS = 20
"""The flood's sockets: more than the places, so that it always has one waiting to take a place."""

FLOOD = Path(__file__).resolve().parents[1] / "benchmarks" / "silent_flood.py"
"""Holds sockets to the port, sending nothing, and connects again as soon as one is closed."""


def flooding(port: int, source: str = "127.0.0.1") -> subprocess.Popen:
    """The flood's process from address `source`, once all its sockets are connected."""
    command = [sys.executable, str(FLOOD), str(port), str(FLOOD_SOCKETS), source]
    flood = subprocess.Popen(command, stdout=subprocess.PIPE)
    assert flood.stdout.readline() == b"connected\n"
    return flood


def evicted_past(served: Served, count: int) -> None:
    """Wait until `count` more connections than now have given their places (the flood churning)."""
    goal = served.call(served.server.health)["evicted"] + count
    deadline = time.monotonic() + 20
    while served.call(served.server.health)["evicted"] < goal:
        assert time.monotonic() < deadline, served.call(served.server.health)
        time.sleep(0.02)


def test_a_connector_that_connected_first_keeps_its_place_while_it_waits_through_a_flood(served):
    (waiting,) = held(served, 1)
    flood = flooding(served.port)
    try:
        evicted_past(served, 4 * MAX_CONNECTIONS)  # the flood has gone round every place four times
        time.sleep(0.3)
        played(waiting, 1)  # its first message, answered Code 200
        for number in range(2, 5):  # connectors that connect during the flood and send at once still get in
            reply, _ = new_connector_shot(served.port, number)
            assert reply["Code"] == 200 and reply["ShotNumber"] == number, reply
    finally:
        flood.kill()
        flood.wait()
        waiting.close()


def test_the_first_connections_keep_their_places_the_newer_ones_give_way_oldest_first(served):
    first = held(served, WAITING_KEPT)
    newer = held(served, MAX_CONNECTIONS - WAITING_KEPT)
    for number in range(1, 3 * MAX_CONNECTIONS):  # connectors in turn, each sending at once, then leaving
        reply, _ = new_connector_shot(served.port, number)
        assert reply["Code"] == 200, reply
    data, _ = until_closed(newer[0], timeout_s=5)  # the oldest of the newer ones went first
    assert "sent no valid message since it connected" in refusal(data, EVICTED)["Message"]
    for number, sock in enumerate(first):  # still connected: their first shots are answered
        played(sock, 100 + number)
    close_all([*first, *newer])


def test_a_connector_that_connects_during_a_flood_from_another_address_keeps_its_place_while_it_waits(served):
    flood = flooding(served.port, "127.0.0.3")
    try:
        evicted_past(served, MAX_CONNECTIONS)
        waiting = socket.create_connection(("127.0.0.1", served.port), timeout=5)  # the bay's own connector
        evicted_past(served, 4 * MAX_CONNECTIONS)  # the flood's own sockets give way to each other
        time.sleep(0.3)
        played(waiting, 5)
        waiting.close()
    finally:
        flood.kill()
        flood.wait()
