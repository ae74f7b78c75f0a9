"""Open Connect's places (issue 42): sockets held idle, or trickling bytes that make no message, give their place to
a new connector when every place is taken (all but the WAITING_KEPT that connected first: issue 55); a connector
that has sent a valid message keeps its place against a flood of new connections. Real TCP sockets on loopback
against a real server (`Served`, as in the limits' tests), and the whole service for /healthz."""

from __future__ import annotations

import socket
import threading
import time

import pytest
from golfflight.service.app import create_app
from golfflight.service.settings import ServiceSettings
from golfflight.service.open_connect.limits import MAX_CONNECTIONS, WAITING_KEPT, ConnectorLimits

from tests.servers import free_port, running
from tests.test_open_connect import HEARTBEAT, encoded, shot
from tests.test_open_connect_limits import Served, connect, objects, refusal, served, until_closed  # noqa: F401 (served: a fixture)

EVICTED = "closed to make room for a new connection"
"""What the Code 503 of a connection that gave its place says."""


def held(served: Served, count: int) -> list[socket.socket]:
    """`count` more sockets connected and taken by the server (no more than there are places), sending nothing."""
    connected = served.call(lambda: len(served.server.connections))
    sockets = [connect(served.port) for _ in range(count)]
    deadline = time.monotonic() + 10
    while served.call(lambda: len(served.server.connections)) < min(connected + count, MAX_CONNECTIONS):
        assert time.monotonic() < deadline, "the server did not take the connections"
        time.sleep(0.02)
    return sockets


def played(sock: socket.socket, number: int) -> None:
    """Send a shot on `sock` and read its Code 200: a valid message, just now."""
    sock.sendall(encoded(shot(number)))
    (reply,) = objects(sock.recv(2048))
    assert reply["Code"] == 200 and reply["ShotNumber"] == number, reply


def new_connector_shot(port: int, number: int) -> tuple[dict, float]:
    """A connector connecting and sending a shot at once: (its reply, seconds from connecting to the reply)."""
    started = time.monotonic()
    sock = connect(port)
    sock.sendall(encoded(shot(number)))
    (reply,) = objects(sock.recv(2048))
    seconds = time.monotonic() - started
    sock.close()
    return reply, seconds


def close_all(sockets: list[socket.socket]) -> None:
    for sock in sockets:
        sock.close()


def test_a_connector_gets_in_past_sixteen_sockets_held_idle(served):
    idle = held(served, MAX_CONNECTIONS)
    reply, seconds = new_connector_shot(served.port, 7)
    assert reply["Code"] == 200 and reply["ShotNumber"] == 7 and seconds < 1.0, (reply, seconds)
    data, _ = until_closed(idle[WAITING_KEPT], timeout_s=5)  # the oldest past those kept gave its place, saying why
    assert "sent no valid message since it connected" in refusal(data, EVICTED)["Message"]
    health = served.call(served.server.health)
    assert health["max_connections"] == MAX_CONNECTIONS and health["refused"] == 0 and health["evicted"] == 1
    assert health["connected"] in (MAX_CONNECTIONS - 1, MAX_CONNECTIONS)  # the connector's close may be on its way
    close_all(idle)


class Trickle:
    """Sends one byte a second on each socket (the bytes of a heartbeat: no message ends in the test's time)."""

    def __init__(self, sockets: list[socket.socket]):
        self.sockets = sockets
        self.stop = threading.Event()
        self.rounds = 0
        self.thread = threading.Thread(target=self._run)
        self.thread.start()

    def _run(self) -> None:
        data = encoded(HEARTBEAT)
        while not self.stop.is_set():
            for sock in self.sockets:
                try:
                    sock.send(data[self.rounds : self.rounds + 1])
                except OSError:
                    pass  # given up its place, and closed
            self.rounds += 1
            self.stop.wait(1.0)

    def close(self) -> None:
        self.stop.set()
        self.thread.join()


def test_a_connector_gets_in_past_sixteen_sockets_trickling_a_byte_a_second(served):
    trickling = held(served, MAX_CONNECTIONS)
    trickle = Trickle(trickling)
    try:
        while trickle.rounds < 3:
            time.sleep(0.1)
        reply, seconds = new_connector_shot(served.port, 8)
        assert reply["Code"] == 200 and reply["ShotNumber"] == 8 and seconds < 1.0, (reply, seconds)
        refusal(until_closed(trickling[WAITING_KEPT], timeout_s=5)[0], EVICTED)
    finally:
        trickle.close()
        close_all(trickling)


def test_a_flood_of_new_connections_never_pushes_out_a_connector_that_played(engine):
    """A connector quiet past the protection (here 0.2 s) still outlasts every connection that never sent a
    message: the flood's own connections give way to each other."""
    served = Served(engine, ConnectorLimits(protected_s=0.2))
    try:
        connector = connect(served.port)
        played(connector, 1)
        idle = held(served, MAX_CONNECTIONS - 1)
        time.sleep(0.3)  # no longer protected: only the order keeps its place
        flood = [connect(served.port) for _ in range(3 * MAX_CONNECTIONS)]
        deadline = time.monotonic() + 10
        while served.call(served.server.health)["evicted"] < 3 * MAX_CONNECTIONS:
            assert time.monotonic() < deadline, served.call(served.server.health)
            time.sleep(0.02)
        played(connector, 2)  # still connected, still answered
        assert served.call(served.server.health)["connected"] == MAX_CONNECTIONS
        close_all([connector, *idle, *flood])
    finally:
        served.close()


def test_when_every_connection_played_the_quietest_past_the_protection_gives_way(engine):
    served = Served(engine, ConnectorLimits(protected_s=0.2))
    try:
        connectors = held(served, MAX_CONNECTIONS)
        for number, sock in enumerate([*connectors, connectors[0]]):  # the first plays again, last
            played(sock, number)
        time.sleep(0.3)  # none protected
        reply, _ = new_connector_shot(served.port, 99)
        assert reply["Code"] == 200
        data, _ = until_closed(connectors[1], timeout_s=5)  # quiet the longest, though not connected the longest
        assert "sent no valid message for" in refusal(data, EVICTED)["Message"]
        played(connectors[0], 100)
        close_all(connectors)
    finally:
        served.close()


def test_healthz_reports_open_connect_connections_refusals_and_evictions():
    port = free_port()
    with running(create_app(ServiceSettings(connect_port=port))) as http:
        assert http.get("/healthz").json()["open_connect"] == {
            "connected": 0, "max_connections": MAX_CONNECTIONS, "refused": 0, "evicted": 0}
        idle = [connect(port) for _ in range(MAX_CONNECTIONS)]
        for sock in idle:  # a message that is not valid: the connection is taken, and stays unprotected
            sock.sendall(b'{"ShotNumber": "seven"}')
            assert objects(sock.recv(2048))[0]["Code"] == 500
        reply, _ = new_connector_shot(port, 5)
        assert reply["Code"] == 200
        report = http.get("/healthz").json()["open_connect"]
        assert report["evicted"] == 1 and report["refused"] == 0 and report["max_connections"] == MAX_CONNECTIONS
        assert report["connected"] >= MAX_CONNECTIONS - 1  # the connector's own close may not have arrived yet
        close_all(idle)
