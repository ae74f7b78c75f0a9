"""Half an object followed at once by a whole shot (issue 55, item 10): the shot was framed as part of the unfinished
object, so it got no reply, and its resend got two (the unfinished object's refusal and the resend's reply). Now
the unfinished object gets one refusal and the shot its reply at once, wherever the cut fell, and the resend gets
one. The framer over every cut of three messages, and real TCP sockets on loopback against a real server."""

from __future__ import annotations

import json
import socket
import time

import pytest
from golfflight.service.open_connect.framing import ObjectFramer, Refused

from tests.test_open_connect import HEARTBEAT, encoded, shot
from tests.test_open_connect_limits import connect, objects, served  # noqa: F401 (served: a fixture)

SPACED = encoded(shot(7))
COMPACT = json.dumps(shot(8), separators=(",", ":")).encode()


@pytest.mark.parametrize("whole", [SPACED, COMPACT, encoded(HEARTBEAT)], ids=["spaced", "compact", "heartbeat"])
def test_every_cut_followed_by_the_whole_message_gives_one_refusal_then_the_message(whole):
    for cut in range(1, len(whole)):
        for pieces in ([whole[:cut] + whole], [whole[:cut], whole]):  # in one read, or in two
            framer = ObjectFramer()
            found = [item for piece in pieces for item in framer.feed(piece)]
            assert len(found) == 2 and isinstance(found[0], Refused) and found[1] == whole, (whole[:cut], found)
            assert "incomplete JSON object" in found[0].message and not framer.partial


def replies(sock: socket.socket, count: int, quiet_s: float = 0.3) -> list[dict]:
    """The replies read until `count` have come and `quiet_s` passed with nothing more (or 10 s)."""
    data, deadline = b"", time.monotonic() + 10
    sock.settimeout(quiet_s)
    while time.monotonic() < deadline:
        try:
            received = sock.recv(65536)
        except TimeoutError:
            if len(objects(data)) >= count:
                break
            continue
        if not received:
            break
        data += received
    return objects(data)


CUTS = {
    "in a string": SPACED.index(b"Connector") + 3,
    "after a key's colon": SPACED.index(b'"ShotNumber":') + len(b'"ShotNumber":'),
    "after a comma": SPACED.index(b'"ShotNumber"'),
    "after a member's colon": SPACED.index(b"167"),
    "in a number": SPACED.index(b"167") + 2,
    "half": len(SPACED) // 2,
}


@pytest.mark.parametrize("cut", CUTS.values(), ids=CUTS.keys())
def test_half_a_shot_then_the_shot_at_once_gets_its_reply_and_the_resend_one(served, cut):
    sock = connect(served.port)
    sock.sendall(SPACED[:cut])
    sock.sendall(SPACED)
    first = replies(sock, 2)
    assert [reply["Code"] for reply in first] == [500, 200] and first[1]["ShotNumber"] == 7, first
    assert "incomplete JSON object" in first[0]["Message"]
    sock.sendall(SPACED)  # the resend: its one reply
    assert [(reply["Code"], reply["ShotNumber"]) for reply in replies(sock, 1)] == [(200, 7)]
    sock.close()
