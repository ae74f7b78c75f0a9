"""GSPro Open Connect's limits and its player information push, on real TCP sockets on loopback: an
`OpenConnectServer` answering with the shipped model (`fly_message` on a `FlightEngine`) on its own event loop in a
thread, as the service's loop runs it, and clients that behave as connectors do, or as hostile programs do."""

from __future__ import annotations

import asyncio
import json
import socket
import threading
import time
from collections.abc import Callable, Iterator

import pytest
from golfflight.contract.gspro import fly_message
from golfflight.flight.engine import FlightEngine
from golfflight.service.open_connect.framing import MAX_MESSAGE_BYTES
from golfflight.service.open_connect.limits import (
    BYTE_BURST,
    LINGER_S,
    MAX_CONNECTIONS,
    MESSAGE_BURST,
    UNREAD_LIMIT_S,
    UNREAD_REPLY_BYTES,
    ConnectorLimits,
)
from golfflight.service.open_connect.server import ConnectAddress, OpenConnectServer

from golfflight.commands.serve import fast_io
from tests.test_open_connect import HEARTBEAT, encoded, shot

EMPTY = b'{"a":{}}'
"""The cheapest object to send: valid JSON, no ball data, no reply."""


class Served:
    """An OpenConnectServer with the real engine's answer and `limits` (default the module's), on an event loop of
    its own thread (the loop `golfflight serve` runs: uvloop where installed)."""

    def __init__(self, engine: FlightEngine, limits: ConnectorLimits | None = None):
        if fast_io()["loop"] == "uvloop":
            import uvloop

            self.loop = uvloop.new_event_loop()
        else:
            self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.server = OpenConnectServer(lambda message, client: fly_message(engine, message), limits)
        self.on_loop(self.server.start(ConnectAddress(0)))
        self.port = self.server.port

    def on_loop(self, coroutine):
        return asyncio.run_coroutine_threadsafe(coroutine, self.loop).result(timeout=30)

    def call(self, function: Callable, *args):
        """`function(*args)` run on the server's loop thread (where the service calls it), its result."""
        async def call():
            return function(*args)

        return self.on_loop(call())

    def close(self) -> None:
        self.on_loop(self.server.close())
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(timeout=10)
        self.loop.close()


@pytest.fixture()
def served(engine) -> Iterator[Served]:
    served = Served(engine)
    yield served
    served.close()


def connect(port: int) -> socket.socket:
    sock = socket.create_connection(("127.0.0.1", port), timeout=5)
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return sock


def objects(data: bytes) -> list[dict]:
    """The JSON objects written back to back in `data` (all of it: a piece left over fails)."""
    decoder, text, found = json.JSONDecoder(), data.decode(), []
    position = 0
    while position < len(text):
        item, position = decoder.raw_decode(text, position)
        found.append(item)
    return found


def until_closed(sock: socket.socket, timeout_s: float) -> tuple[bytes, float]:
    """Everything the server writes until it closes the connection, and the seconds that took."""
    started, data = time.monotonic(), b""
    sock.settimeout(timeout_s)
    while True:
        try:
            received = sock.recv(65536)
        except ConnectionResetError:
            break
        if not received:
            break
        data += received
    return data, time.monotonic() - started


def refusal(data: bytes, says: str) -> dict:
    (reply,) = objects(data)
    assert reply["Code"] == 503 and says in reply["Message"], reply
    return reply


@pytest.mark.parametrize("flood", [EMPTY, encoded(HEARTBEAT)], ids=["empty objects", "heartbeats"])
def test_a_flood_of_messages_gets_one_refusal_and_a_close(served, flood):
    sock = connect(served.port)
    sock.sendall(flood * (3 * MESSAGE_BURST))  # messages that get no reply, many at once
    data, seconds = until_closed(sock, timeout_s=5)
    reply = refusal(data, f"more than {MESSAGE_BURST} messages at once")
    assert "send one message at a time" in reply["Message"] and seconds < LINGER_S + 1
    sock.close()


def test_a_stream_that_never_ends_an_object_is_refused_for_its_bytes(served):
    sock = connect(served.port)
    try:  # one object over the size limit, which the framer skips to its end: no messages, only bytes
        sock.sendall(b'{"a": "' + b"x" * (2 * BYTE_BURST))
    except (BrokenPipeError, ConnectionResetError):
        pass  # closed while still sending
    data, _ = until_closed(sock, timeout_s=5)
    oversized, refused = objects(data)
    assert oversized["Code"] == 500 and f"message over {MAX_MESSAGE_BYTES:,} bytes" in oversized["Message"]
    assert refused["Code"] == 503 and f"more than {BYTE_BURST:,} bytes at once" in refused["Message"]
    sock.close()


def test_a_hostile_loop_refused_again_and_again_is_logged_once(served, caplog):
    for _ in range(3):
        sock = connect(served.port)
        sock.sendall(EMPTY * (3 * MESSAGE_BURST))
        refusal(until_closed(sock, timeout_s=5)[0], "messages at once")
        sock.close()
    assert [r.getMessage() for r in caplog.records if "too fast" in r.getMessage()] == [
        "GSPro Open Connect: a connector sent messages too fast: closed"
    ]


def test_shots_past_the_rate_are_answered_in_order_until_it_then_refused(engine):
    """The bucket refills while shots fly: more than the burst are answered, as many as fit in the burst and the
    rate, then one refusal. The rate here is 5 a second, so that what refills while the shots fly stays far below
    the shots sent on any machine (at the real 200 a second a machine flying a shot in 4.7 ms refilled faster than
    shots flew, and every one was answered)."""
    burst, rate, shots = 20, 5.0, 200
    served = Served(engine, ConnectorLimits(message_burst=burst, messages_per_s=rate))
    try:
        sock = connect(served.port)
        sock.sendall(b"".join(encoded(shot(n)) for n in range(shots)))
        data, _ = until_closed(sock, timeout_s=30)
        *answered, refused = objects(data)
        assert burst <= len(answered) < shots
        assert [r["ShotNumber"] for r in answered] == list(range(len(answered)))
        assert {r["Code"] for r in answered} == {200} and refused["Code"] == 503
        sock.close()
    finally:
        served.close()


def test_a_connector_is_answered_within_a_second_after_a_flood_on_another_connection(served):
    flooded = threading.Event()

    def flood() -> None:
        sock = connect(served.port)
        try:
            for _ in range(40):  # 10 MB
                sock.sendall(EMPTY * 32768)
                flooded.set()
        except OSError:
            pass  # closed by the server
        finally:
            flooded.set()
            sock.close()

    flooder = threading.Thread(target=flood)
    flooder.start()
    assert flooded.wait(timeout=5)
    flooder.join(timeout=30)
    sock = connect(served.port)
    started = time.monotonic()
    sock.sendall(encoded(shot(7)))
    sock.settimeout(5)
    (reply,) = objects(sock.recv(2048))
    seconds = time.monotonic() - started
    assert reply["Code"] == 200 and reply["ShotNumber"] == 7 and seconds < 1.0, seconds
    sock.close()


def test_one_connection_more_than_the_limit_while_every_connector_plays_gets_a_refusal_and_a_close(served):
    connected = [connect(served.port) for _ in range(MAX_CONNECTIONS)]
    for number, sock in enumerate(connected):  # a shot answered: each has sent a valid message just now
        sock.sendall(encoded(shot(number)))
        assert objects(sock.recv(2048))[0]["Code"] == 200
    extra = connect(served.port)
    data, _ = until_closed(extra, timeout_s=5)
    refusal(data, f"{MAX_CONNECTIONS} connectors are connected")
    extra.close()
    connected.pop().close()
    deadline = time.monotonic() + 5
    while served.call(lambda: len(served.server.connections)) == MAX_CONNECTIONS:
        assert time.monotonic() < deadline
        time.sleep(0.02)
    again = connect(served.port)  # a place left free is taken again
    again.sendall(encoded(shot(9)))
    (reply,) = objects(again.recv(2048))
    assert reply["Code"] == 200
    for sock in (*connected, again):
        sock.close()


def test_a_connector_that_leaves_its_replies_unread_stops_being_read_then_is_dropped(served):
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.connect(("127.0.0.1", served.port))
    sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    sock.settimeout(0.05)
    sent, dropped = 0, None
    started = time.monotonic()
    while dropped is None and time.monotonic() - started < UNREAD_LIMIT_S + 5:
        try:  # shots at the rate a connector's messages may come, 20 every 0.15 s, never a reply read
            sock.sendall(b"".join(encoded(shot(n)) for n in range(sent, sent + 20)))
            sent += 20
        except TimeoutError:
            pass
        except (BrokenPipeError, ConnectionResetError):
            dropped = time.monotonic() - started
        if sent == 140:
            (connection,) = served.call(lambda: list(served.server.connections))
            buffered = served.call(connection.transport.get_write_buffer_size)
            assert buffered < 2 * UNREAD_REPLY_BYTES, buffered  # reading paused
        time.sleep(0.15)
    assert dropped is not None, f"still connected after {sent} shots"
    assert served.call(lambda: len(served.server.connections)) == 0
    sock.close()


PLAYER = b'{"Code":201,"Message":"GSPro Player Information","Player":{"Handed":"RH","Club":"DR"}}'


def test_player_information_reaches_every_connector_and_nothing_is_pushed_on_connecting(served):
    first, second = connect(served.port), connect(served.port)
    for number, sock in enumerate((first, second), 1):  # a shot answered: the server has taken the connection
        sock.sendall(encoded(HEARTBEAT) + encoded(shot(number)))
        assert objects(sock.recv(2048))[0]["Code"] == 200
    served.call(served.server.send_player, "DR", "RH")  # from the loop's thread, as the service's bay calls it
    for sock in (first, second):
        assert sock.recv(2048) == PLAYER
    served.server.send_player("PT", "LH")  # from another thread
    putting = PLAYER.replace(b'"RH"', b'"LH"').replace(b'"DR"', b'"PT"')
    for sock in (first, second):
        assert sock.recv(2048) == putting
    later = connect(served.port)
    later.sendall(encoded(shot(3)))  # at once: its one read is its shot's reply, not the player sent before
    (reply,) = objects(later.recv(2048))
    assert reply["Code"] == 200
    with pytest.raises(ValueError, match="handed"):
        served.server.send_player("DR", "right")
    with pytest.raises(ValueError, match="club"):
        served.server.send_player("wedge", "RH")
    for sock in (first, second, later):
        sock.close()


class Mlm2ProLike:
    """A connector that reads as MLM2PRO-GSPro-Connector does (github.com/springbok/MLM2PRO-GSPro-Connector,
    src/gspro_connect.py and its message poll): after a shot, one recv(2048) with a
    2 s timeout (two attempts) is its reply; a poll every 250 ms reads whatever else arrives and splits concatenated
    objects. The two never read at once (a lock)."""

    def __init__(self, port: int):
        self.sock = connect(port)
        self.lock = threading.Lock()
        self.polled: list[tuple[float, dict]] = []
        self.stop = threading.Event()
        self.poller = threading.Thread(target=self._poll)
        self.poller.start()

    def _poll(self) -> None:
        while not self.stop.wait(0.25):
            with self.lock:
                self.sock.setblocking(False)
                try:
                    data = self.sock.recv(65536)
                except BlockingIOError:
                    continue
                finally:
                    self.sock.setblocking(True)
            self.polled += [(time.monotonic(), item) for item in objects(data)]

    def send(self, message: dict) -> None:
        self.sock.sendall(encoded(message))

    def shot(self, message: dict) -> bytes:
        """The shot's reply as the connector reads it: one recv(2048)."""
        with self.lock:
            self.send(message)
            self.sock.settimeout(2.0)
            for attempt in range(2):
                try:
                    return self.sock.recv(2048)
                except TimeoutError:
                    if attempt:
                        raise
        raise AssertionError("unreachable")

    def close(self) -> None:
        self.stop.set()
        self.poller.join()
        self.sock.close()


def test_a_connector_reading_as_mlm2pro_does_gets_one_reply_per_shot_and_the_player_information(served):
    connector = Mlm2ProLike(served.port)
    try:
        connector.send(HEARTBEAT)
        for number in range(1, 6):
            data = connector.shot(shot(number, Speed=100.0 + 10 * number))
            (reply,) = objects(data)  # one whole object in the one read
            assert reply["Code"] == 200 and reply["ShotNumber"] == number and len(data) <= 2048
            connector.send(HEARTBEAT)
        sent = time.monotonic()
        served.call(served.server.send_player, "PT", "RH")
        while not connector.polled and time.monotonic() - sent < 1.0:
            time.sleep(0.01)
        time.sleep(0.6)  # two more polls: anything else would show
        assert [item for _, item in connector.polled] == [json.loads(PLAYER.replace(b'"DR"', b'"PT"'))]
        assert connector.polled[0][0] - sent < 1.0
        (reply,) = objects(connector.shot(shot(6)))
        assert reply["Code"] == 200 and reply["ShotNumber"] == 6
    finally:
        connector.close()
