"""What one Open Connect connector may do, and why each bound is where it is.

Open Connect has no authentication: any program on the bay's machine (or on the network, with `--connect-host`) can
open the port. Real connectors send a shot every few seconds at most, a heartbeat every few seconds, a shot again
after 5 s without a reply (up to 10 times: MLM2PRO-GSPro-Connector's early src/gspro_connect.py,
github.com/springbok/MLM2PRO-GSPro-Connector), and reconnect after 5 s when dropped (another open connector's
public source). The bounds below
sit far above that and far below what costs the service anything; each is refused as `server` says (Code 500 for a
message refused while the connection goes on, Code 503 and a close for a connection refused or ended).

Memory per connection: one read of the socket (at most 256 KiB, the event loop's read size: reading pauses until
it is framed), the object being framed (at most MAX_MESSAGE_BYTES), the objects framed from one piece of input
(`server.PIECE_BYTES`), the replies not yet taken (UNREAD_REPLY_BYTES in the process) and one turn's replies: under
half a MiB in the process, and the kernel's buffers (SEND_BUFFER_BYTES, RECEIVE_BUFFER_BYTES). In total:
MAX_CONNECTIONS of them, plus at most MAX_CONNECTIONS refused ones lingering (LINGER_S, LINGER_BYTES) with nothing
but their refusal buffered.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from golfflight.service.open_connect.framing import MAX_MESSAGE_BYTES

MAX_CONNECTIONS = 16
"""Connectors connected at once. A bay has one launch monitor and one connector; 16 leaves room for several bays on
one service and for a connector's reconnect overlapping its old connection. One more takes the place of the
connection that gives way first (`server.OpenConnectServer.admit`: WAITING_KEPT and PROTECTED_S say which), which
gets Code 503 and a close; only when every place is PROTECTED_S-fresh is the new one refused instead (Code 503,
closed)."""

WAITING_KEPT = 4
"""Connections with no valid message yet that keep their places against new connections: the WAITING_KEPT that
connected first. A real connector connects when it starts and sends nothing until the golfer hits (minutes), and
nothing on the wire tells it from a socket held idle; what does is that it stays, while a flood's sockets come and
go. So a connector that connected before a flood (among the first WAITING_KEPT silent ones) keeps its place however
long it waits, while the other silent connections (the newer ones) give way: the oldest of those of the address
that holds the most of them. A flood's sockets from one address so push out only their own, and a connector on
another address that connects during the flood keeps its place while it waits too; one on the flood's own address
(loopback, say) still gets MAX_CONNECTIONS - WAITING_KEPT - 1 = 11 newer connections' time to send its first
message, after which its place is kept as any playing connector's.
Four covers a bay's connector, its reconnect overlapping the old connection and one more; more would let sockets
held idle before anyone connects shrink what newcomers share (16 - 4 = 12 places), fewer would drop a waiting
connector sooner."""

PROTECTED_S = 60.0
"""How long a valid message (a shot, a heartbeat, any message that validates) keeps its connection's place against
new connections once all MAX_CONNECTIONS are taken. Nothing is closed for being quiet while a place is free: a golfer
may not hit for minutes and some connectors send no heartbeat, so any idle timeout would drop real connectors. Under
pressure, a connection that never sent a valid message (an idle socket, one trickling bytes that never make a
message, a new connection that has sent nothing yet) gives way first: those past the WAITING_KEPT that connected
first, the oldest of the address holding the most of them first; then those WAITING_KEPT, the newest first; then one quiet longer than this, the
quietest first. A minute covers a connector's heartbeats (every few seconds) and a golfer's shots, so a flood of new
connections cannot push out a bay that is playing."""

MESSAGES_PER_S = 200.0
"""Messages (objects, and refused pieces of input) a connection may send a second on average: a token bucket
refilled at this rate. Connectors send one or two a second at most; this is a hundred times that. A client that sends
its next shot as soon as the last is answered (a benchmark, not a connector) reaches 300-500 a second and is closed
within a second. Past it: one Code 503 saying so, and a close."""

MESSAGE_BURST = 100
"""The bucket's size: messages a connection may send at once. A connector's messages come one at a time (a shot, a
heartbeat, ten resends 5 s apart); a test client writing a few shots back to back fits too. It also bounds what one
connection costs before it is closed: 100 tiny objects (a few milliseconds), or, written all at once, about 170
shots (the burst and what the rate adds while they fly, a third of a second of flights), then the close."""

BYTES_PER_S = 256 * 1024
"""Bytes a connection may send a second on average (a second token bucket): a connector sends under a kilobyte a
second. Input that makes no messages (whitespace, or the rest of an object over MAX_MESSAGE_BYTES, which is skipped)
costs framing too, and only this bounds it. Past it: one Code 503 saying so, and a close."""

BYTE_BURST = 1024 * 1024
"""Bytes a connection may send at once: sixteen of the largest messages accepted."""

UNREAD_REPLY_BYTES = 16 * 1024
"""Replies buffered in the process, not taken by the connector, past which the connection is no longer read
(about 20 replies of about 800 bytes): a connector reads each reply before its next shot."""

SEND_BUFFER_BYTES = 16 * 1024
"""The kernel's send buffer asked for each connection (SO_SNDBUF; Linux doubles it). Left alone, Linux grows it to
megabytes on loopback, thousands of replies a connector that never reads would leave queued before reading
paused."""

RECEIVE_BUFFER_BYTES = 64 * 1024
"""The kernel's receive buffer asked for each connection (SO_RCVBUF; Linux doubles it): a hundred messages and
more. Left alone, Linux grows it to megabytes for a sender that writes faster than it is read."""

UNREAD_LIMIT_S = 2.0
"""How long reading may stay paused for replies the connector does not take before the connection is dropped (no
reply: it would not be read). By then it has left dozens of replies unread (these buffers and the kernel's at both
ends full), which no connector does; one that reads (MLM2PRO-GSPro-Connector polls every 250 ms) takes them in
milliseconds."""

LINGER_S = 1.0
"""How long a connection refused with a Code 503 is still read (and what comes dropped) after its refusal is sent
and its side closed, so that the refusal arrives before the close: closing a socket with unread input resets it,
and a reset can discard the refusal at the other end before it is read (Windows, where connectors run, does)."""

LINGER_BYTES = 64 * 1024
"""What a refused connection may still send while it lingers: a connector stops at the refusal with at most a few
messages on their way; a sender that goes on past this is not reading it, and is reset at once."""


@dataclass(frozen=True)
class ConnectorLimits:
    """The bounds one `OpenConnectServer` applies (the module's constants unless told otherwise, e.g. by a test)."""

    max_connections: int = MAX_CONNECTIONS
    max_message_bytes: int = MAX_MESSAGE_BYTES
    messages_per_s: float = MESSAGES_PER_S
    message_burst: int = MESSAGE_BURST
    bytes_per_s: float = BYTES_PER_S
    byte_burst: int = BYTE_BURST
    unread_reply_bytes: int = UNREAD_REPLY_BYTES
    send_buffer_bytes: int = SEND_BUFFER_BYTES
    receive_buffer_bytes: int = RECEIVE_BUFFER_BYTES
    unread_limit_s: float = UNREAD_LIMIT_S
    linger_s: float = LINGER_S
    linger_bytes: int = LINGER_BYTES
    protected_s: float = PROTECTED_S
    waiting_kept: int = WAITING_KEPT

    def too_many_connections(self) -> str:
        return (f"{self.max_connections} connectors are connected to this golfflight already (the most it takes at "
                f"once), each with a message in the last {self.protected_s:g} s: close one, or connect again after "
                "one has left")

    def evicted(self, quiet_s: float, ever: bool) -> str:
        """Why a connection `quiet_s` seconds without a valid message (`ever`: it sent one before that) was closed."""
        since = f"for {quiet_s:.0f} s" if ever else f"since it connected {quiet_s:.0f} s ago"
        return (f"closed to make room for a new connection: {self.max_connections} were connected (the most this "
                f"golfflight takes at once) and this one had sent no valid message {since}: connect again and send "
                "your shots")

    def too_many_messages(self) -> str:
        return (f"more than {self.message_burst} messages at once or {self.messages_per_s:g} a second on this "
                "connection (a connector sends a shot or a heartbeat every few seconds): closed; connect again and "
                "send one message at a time")

    def too_many_bytes(self) -> str:
        return (f"more than {self.byte_burst:,} bytes at once or {self.bytes_per_s:,.0f} a second on this connection "
                "(a connector's message is under a kilobyte): closed; connect again and send messages, not a stream")


class TokenBucket:
    """`take` says whether `n` more (messages, bytes) fit: `burst` at once, `rate` a second on average."""

    def __init__(self, rate: float, burst: int):
        self.rate = rate
        self.burst = burst
        self._tokens = float(burst)
        self._at = time.monotonic()

    def take(self, n: int = 1) -> bool:
        now = time.monotonic()
        self._tokens = min(self.burst, self._tokens + (now - self._at) * self.rate)
        self._at = now
        if self._tokens < n:
            return False
        self._tokens -= n
        return True
