"""The TCP listener: one protocol object per connector connection, objects framed as they arrive, one reply per shot,
each connection held to `limits.ConnectorLimits`, and the player information pushed to every connector.

It runs on the HTTP service's event loop, opened and closed by the app's lifespan, not in a process of its own: the
model is loaded once, TCP shots count in /v1/latency with HTTP's, and whatever the app does with its shots sees
these too. `answer` is called on that loop's thread, as the HTTP routes' own calls are; `send_player` may be called
from any thread. Each connection is an `asyncio.Protocol`: a shot arriving in one piece is framed and answered in
the callback that receives it, with no stream buffer, task or wake-up between the socket and the reply
(docs/benchmarks.md, issue 25).

Isolation from HTTP: Open Connect works in bounded turns. Input is framed PIECE_BYTES at a time, and all connections
together work (frame, answer) at most TURN_S (plus one piece or one shot) in one turn of the event loop, in round
robin; what is left waits for the next turn (`loop.call_soon`: behind every callback already ready, HTTP's among
them) with reading paused, so one read of the socket is the most a connection holds. However many connections
flood, each of an HTTP request's callbacks waits for one turn at most. Before, one callback framed and answered a
whole read (256 KiB: 30,000 tiny objects), and a connector writing 20 MB of `{"a":{}}` held HTTP single shots for
seconds (`benchmarks/bench_hostile.py`: p99 7.7 to 29 s over four runs, a reset connection, /healthz unanswered up
to 10 s after the flood stopped). The turns bound the time; the token buckets (`limits`: messages and bytes) bound
the work: a flood is closed once one is empty, whatever it sends next.

Chosen by measurement over a thread with its own event loop (the same connections, turns and limits on uvloop in a
second thread, `answer` there), on the 2-core machine a minute apart, the same hostile connectors (bench_hostile's
(b) and (c)): with the thread, HTTP single shots took p99 29 ms, max 142 ms under the flood of empty objects and a
connector that never reads, and p99 75 ms, max 130 ms under heartbeats, 2,502 and 1,198 of them answered in the
10 s; in turns on the one loop, p99 5.2 and 4.8 ms, max 10 and 11 ms, 3,681 and 4,759 answered. In one process the
two loops share the GIL: a thread busy framing holds it for up to the interpreter's switch interval (5 ms) each time
the HTTP thread, which lets go of it at every system call and every ONNX Runtime call of a flight, wants it back.
The turns also keep `answer` on the loop the rest of the service runs on, so it need not be thread-safe.

Places: MAX_CONNECTIONS connections are served at once, and nothing is closed for being quiet (a golfer may not hit
for minutes; some connectors send no heartbeat). A new connection when every place is taken is admitted on
probation: it takes the place of the connection that gives way first (`OpenConnectServer._giving_way`: of those that
never sent a valid message, past the `limits.WAITING_KEPT` that connected first, the oldest of the address holding
the most; then those kept, the newest first; then the quietest), which gets Code 503 saying why and a close; a connection with a valid message in
the last `limits.PROTECTED_S` never gives way, and when all are so, the new one is refused instead. So sixteen
sockets held idle, or trickling bytes that make no message, lose their places to the next connector; a flood of new
connections pushes out only its own (they never send a message), never a connector that is playing nor one that
connected before it and waits for its golfer, nor, from another address, one that connected during it. A program that sends valid messages on sixteen sockets looks like
sixteen connectors: with no authentication, nothing tells them apart.
"""

from __future__ import annotations

import asyncio
import logging
import socket
import time
from collections import Counter, deque
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

from golfflight.contract.gspro import GSProReply
from golfflight.service.open_connect.framing import ObjectFramer, Refused
from golfflight.service.open_connect.limits import ConnectorLimits, TokenBucket
from golfflight.service.open_connect.replies import Replied, encoded, player_information, reply_to

PAUSE_S = 2.0
"""Silence after which a half-received object counts as paused (`ObjectFramer.stall`): a connector writes a message
in one go, so its pieces arrive within milliseconds. Nothing is refused at the pause: what comes next is either the
rest of the object (answered as usual) or a new object, and then the unfinished one gets one refusal before the new
one is read."""
PIECE_BYTES = 1024
"""Input framed at a time. Framing is pure Python for anything but one whole object in one piece: 1 KiB of the
cheapest objects to send (`{"a":{}}`, 128 of them) takes about 0.6 ms on the 2-core machine, 1.4 times that since
the framer finds a new object after an unfinished one (issue 55: docs/reliability.md § 10), a connector's shot
(about 600 bytes, one piece) a few microseconds."""
TURN_S = 0.001
"""Open Connect's work (every connection's together) in one turn of the event loop, before everything else that is
ready runs (HTTP requests among them): a turn lasts TURN_S plus at most one piece's framing or one shot's flight."""
LOG_EVERY_S = 10.0
"""Least time between two log lines about one kind of event (a connector coming or going, a refusal): a hostile
program's loop connects and is refused hundreds of times a second and would fill the log; each line says how many
were not logged since the last."""
INTERNAL_ERROR = "internal error while answering this message (the server log has the details)"

log = logging.getLogger(__name__)


class ThrottledLog:
    """Logs each kind of event (its message) at most once per LOG_EVERY_S, with the count of those not logged: a
    connector's coming and going, each kind of refusal."""

    def __init__(self):
        self._last: dict[str, float] = {}
        self._unlogged: dict[str, int] = {}

    def warning(self, message: str) -> None:
        self._log(logging.WARNING, message, message)

    def info(self, message: str, kind: str) -> None:
        """`message` at INFO, throttled with every other message of its `kind`."""
        self._log(logging.INFO, message, kind)

    def _log(self, level: int, message: str, kind: str) -> None:
        now = time.monotonic()
        if kind in self._last and now - self._last[kind] < LOG_EVERY_S:
            self._unlogged[kind] = self._unlogged.get(kind, 0) + 1
            return
        self._last[kind] = now
        unlogged = self._unlogged.pop(kind, 0)
        more = f" ({unlogged:,} more since the last such line)" if unlogged else ""
        log.log(level, "GSPro Open Connect: %s%s", message, more)


@dataclass(frozen=True)
class ConnectAddress:
    """Where to listen for connectors: loopback unless told otherwise (the protocol has no authentication)."""

    port: int
    host: str = "127.0.0.1"


ClientAnswer = Callable[..., GSProReply]
"""Flies a message that carries BallData, called `answer(message, client=address)`: the service's shared GSPro
answer, told the connector's address (its shots' share of the session memory, `service.runtime.shares`)."""


class OpenConnectServer:
    """GSPro Open Connect v1 on a TCP port; `answer` flies each message that carries a shot (called on the event
    loop's thread that `start` ran on, with the connector's address). `limits` bound what each connector may do
    (default `limits.ConnectorLimits()`: the module's constants)."""

    def __init__(self, answer: ClientAnswer, limits: ConnectorLimits | None = None):
        self.answer = answer
        self.limits = limits or ConnectorLimits()
        self._server: asyncio.Server | None = None
        self._loop: asyncio.AbstractEventLoop | None = None
        self.connections: set[Connection] = set()  # served now; each leaves when it closes or is refused
        self.refused: set[Connection] = set()  # refused (Code 503), their refusal on its way, until closed
        self.events = ThrottledLog()  # connectors coming and going, refusals: logged, throttled
        self.refused_total = 0  # connections refused or closed for a limit (Code 503), since start
        self.evicted_total = 0  # connections closed for a new one's place (Code 503), since start
        self._waiting: deque[Connection] = deque()  # connections with input left, in the order their turns come
        self._turn: asyncio.Handle | None = None  # the next turn of all Open Connect work, scheduled

    async def start(self, address: ConnectAddress, *, listening: bool = True) -> None:
        """Take the port (OSError when it cannot be had) and accept connectors on it, or with `listening` False only
        take it, so that a port that cannot be had stops a startup early, until `listen`."""
        self._loop = asyncio.get_running_loop()
        self._server = await self._loop.create_server(
            lambda: Connection(self), address.host, address.port, start_serving=listening
        )

    async def listen(self) -> None:
        """Accept connectors on the port `start(..., listening=False)` took."""
        await self._server.start_serving()

    @property
    def port(self) -> int:
        """The port listened on."""
        return self._server.sockets[0].getsockname()[1]

    async def close(self) -> None:
        """Stop listening and close every connection (replies already written still go out, to connectors that
        read them)."""
        self._server.close()
        for connection in [*self.connections, *self.refused]:
            connection.close()
        await self._server.wait_closed()

    def send_player(self, club: str, handed: str) -> None:
        """Push GSPro's player information, `{"Code":201,"Message":"GSPro Player Information","Player":{"Handed":
        handed,"Club":club}}`, to every connector connected now. Nothing is pushed to a connector as it connects: one
        that reads a single reply after each shot (MLM2PRO-GSPro-Connector's `recv(2048)`) would take an object it
        did not ask for as its shot's reply if its shot followed at once. `club` is a GSPro club code (DR, I7, PT,
        ...), `handed` RH or LH; InputError otherwise. Safe to call from any thread: off the event loop's thread,
        the push is handed to the loop (`call_soon_threadsafe`) and goes out on its next turn."""
        data = player_information(club, handed)
        try:
            running = asyncio.get_running_loop()
        except RuntimeError:
            running = None
        if self._loop is None or running is self._loop:
            self._push(data)
        else:
            self._loop.call_soon_threadsafe(self._push, data)

    def _push(self, data: bytes) -> None:
        for connection in self.connections:
            if not connection.transport.is_closing():  # one dropped (`_drop_unread`) leaves at the loop's next turn
                connection.transport.write(data)

    def health(self) -> dict:
        """Open Connect's figures for GET /healthz: connections served now, the most served at once, and since start
        the connections refused or closed for a limit (Code 503) and those closed to make room for a new one."""
        return {"connected": len(self.connections), "max_connections": self.limits.max_connections,
                "refused": self.refused_total, "evicted": self.evicted_total}

    def refuse(self, connection: Connection, logged: str, message: str) -> None:
        """Refuse `connection` for a limit: Code 503 `message`, then the close; `logged` goes to the log (at most
        once per LOG_EVERY_S)."""
        self.events.warning(logged)
        self.refused_total += 1
        connection.refuse(message)

    def admit(self, connection: Connection) -> None:
        """Serve a new connection (its buffers bounded), in the place of one that gives way when MAX_CONNECTIONS
        are served already (`_make_room`), or refuse it when none does."""
        if len(self.connections) >= self.limits.max_connections and not self._make_room(connection):
            logged = f"a connection refused, {self.limits.max_connections} connected already, each of them playing"
            self.refuse(connection, logged, self.limits.too_many_connections())
            return
        self.connections.add(connection)
        transport = connection.transport
        sock = transport.get_extra_info("socket")
        if sock is not None:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, self.limits.send_buffer_bytes)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, self.limits.receive_buffer_bytes)
        transport.set_write_buffer_limits(high=self.limits.unread_reply_bytes)

    def _make_room(self, new: Connection) -> bool:
        """Free a place for the `new` connection: end one closing already (its connector left, or it was dropped), or
        close the one that gives way first (Code 503 saying why); False when every connection is protected (a valid
        message in the last `limits.PROTECTED_S`)."""
        leaving = next((connection for connection in self.connections if connection.transport.is_closing()), None)
        if leaving is not None:  # aborted: a close may wait for ever on replies its connector does not read
            leaving.transport.abort()
            self.connections.discard(leaving)
            return True
        now = time.monotonic()
        quitting = self._giving_way(now, new.client)
        if quitting is None:
            return False
        self.events.warning("a connection closed to make room for a new one")
        self.evicted_total += 1
        quitting.refuse(self.limits.evicted(now - quitting.last_heard, quitting.last_message is not None))
        return True

    def _giving_way(self, now: float, client: str) -> Connection | None:
        """The connection that gives its place to a new one from address `client`: of those with no valid message
        yet, past the `limits.WAITING_KEPT` that connected first, the oldest of the address holding the most of
        them (the new one counted with its own); else the newest of those kept; else the quietest unprotected one
        that sent one; None when every connection is protected."""
        waiting = sorted((c for c in self.connections if c.last_message is None), key=lambda c: c.admitted)
        kept, newer = waiting[: self.limits.waiting_kept], waiting[self.limits.waiting_kept :]
        if newer:
            held = Counter(c.client for c in newer)
            held[client] += 1
            return max(newer, key=lambda c: held[c.client])  # the first (oldest) of the most held
        if kept:
            return kept[-1]
        exposed = [c for c in self.connections if not c.protected(now)]
        return min(exposed, key=lambda c: c.last_message, default=None)

    def busy(self) -> bool:
        """Whether some connection waits for its turn (then a new arrival waits too, behind it)."""
        return self._turn is not None

    def wait_turn(self, connection: Connection) -> None:
        """Put `connection`, which has input left, in line for the next turn."""
        self._waiting.append(connection)
        if self._turn is None:
            self._turn = self._loop.call_soon(self._take_turn)

    def _take_turn(self) -> None:
        """One turn, in the event loop, for all connections together: each in line works, in order, until TURN_S
        has passed; those with input left go to the back of the line, for the next turn (scheduled once: `_turn`
        stays set while this one runs)."""
        deadline = time.perf_counter() + TURN_S
        while self._waiting and time.perf_counter() < deadline:
            self._waiting.popleft().work(deadline)
        self._turn = self._loop.call_soon(self._take_turn) if self._waiting else None

    def reply(self, item: bytes | Refused, client: str) -> Replied:
        """`reply_to` for a connection from address `client`, with any unexpected failure answered (and logged)
        instead of ending the connection."""
        try:
            return reply_to(item, partial(self.answer, client=client))
        except Exception:
            log.exception("GSPro Open Connect: answering a message failed")
            return Replied(GSProReply(Code=500, Message=INTERNAL_ERROR), False)


def _peer(transport: asyncio.Transport) -> str:
    """The connection's other end as host:port, for the log."""
    peer = transport.get_extra_info("peername")
    return f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) and len(peer) >= 2 else "an unknown address"


class Connection(asyncio.Protocol):
    """One connector's connection. What arrives is framed PIECE_BYTES at a time and answered in order: at once while
    no other connection waits, up to TURN_S, then in the server's turns; while input is left for a later turn, or
    the connector leaves its replies unread, the socket is not read. A pause of PAUSE_S mid-object marks it stalled
    (`ObjectFramer.stall`). Refused (too many connections, messages or bytes) or giving its place to a new one: one
    Code 503, then the close (`refuse`); replies left unread UNREAD_LIMIT_S: dropped. `last_message` (time.monotonic) is when it last sent a
    valid message: what keeps its place when a new connection needs one (`OpenConnectServer.admit`)."""

    def __init__(self, server: OpenConnectServer):
        self.server = server
        self.limits = server.limits
        self.framer = ObjectFramer(self.limits.max_message_bytes)
        self.messages = TokenBucket(self.limits.messages_per_s, self.limits.message_burst)
        self.bytes = TokenBucket(self.limits.bytes_per_s, self.limits.byte_burst)
        self.transport: asyncio.Transport | None = None
        self._input, self._at = b"", 0  # the last read, framed up to _at
        self._items: deque[bytes | Refused] = deque()  # framed, not yet answered
        self._reading = True
        self._writing = True  # False while the connector leaves its replies unread (pause_writing)
        self._waiting = False  # in the server's line for a turn
        self._pause: asyncio.TimerHandle | None = None  # PAUSE_S mid-object
        self._unread: asyncio.TimerHandle | None = None  # UNREAD_LIMIT_S of replies left unread
        self._ending: asyncio.TimerHandle | None = None  # LINGER_S after a refusal
        self._lingered = 0  # bytes dropped since the refusal
        self.client = ""  # the connector's address (`connection_made`): its shots' share of the session memory
        self.admitted = time.monotonic()
        self.last_message: float | None = None

    @property
    def last_heard(self) -> float:
        """When it last sent a valid message, or, having sent none, connected (time.monotonic)."""
        return self.admitted if self.last_message is None else self.last_message

    def protected(self, now: float) -> bool:
        """Whether its place is kept against new connections: a valid message in the last PROTECTED_S."""
        return self.last_message is not None and now - self.last_message < self.limits.protected_s

    def connection_made(self, transport: asyncio.Transport) -> None:
        self.transport = transport
        peer = transport.get_extra_info("peername")
        self.client = peer[0] if isinstance(peer, tuple) and peer else ""
        self.server.admit(self)
        if self in self.server.connections:
            self.server.events.info(f"a connector connected from {_peer(transport)} "
                                    f"({len(self.server.connections)} connected)", "connected")

    def data_received(self, data: bytes) -> None:
        if self._ending is not None:  # refused: what still comes is dropped, up to LINGER_BYTES
            self._lingered += len(data)
            if self._lingered > self.limits.linger_bytes:
                self.transport.abort()
            return
        if self._pause is not None:
            self._pause.cancel()
            self._pause = None
        self._input, self._at = self._input[self._at :] + data, 0  # reading pauses while any is left: one read
        if self.server.busy():
            self._after_work()  # in line behind the others
        else:
            self.work(time.perf_counter() + TURN_S)  # a connector's shot: answered in the callback that got it

    def pause_writing(self) -> None:
        self._writing = False
        self._read(False)
        self._unread = asyncio.get_running_loop().call_later(self.limits.unread_limit_s, self._drop_unread)

    def resume_writing(self) -> None:
        self._writing = True
        if self._unread is not None:
            self._unread.cancel()
            self._unread = None
        self._after_work()

    def connection_lost(self, error: Exception | None) -> None:
        for timer in (self._pause, self._unread, self._ending):
            if timer is not None:
                timer.cancel()
        if self in self.server.connections:
            self.server.connections.discard(self)
            self.server.events.info(f"a connector from {_peer(self.transport)} left "
                                    f"({len(self.server.connections)} connected)", "left")
        self.server.refused.discard(self)

    def close(self) -> None:
        """Close (abort, where the connector leaves its replies unread and the close would wait on it for ever); what
        it sent and is not answered yet is dropped."""
        self._items.clear()
        self._input, self._at = b"", 0
        if self._writing:
            self.transport.close()
        else:
            self.transport.abort()

    def refuse(self, message: str) -> None:
        """Answer Code 503 with `message` and close: the connector's side is shut after the reply, and what it still
        sends is read and dropped for LINGER_S, up to LINGER_BYTES (a close with unread input would reset the
        connection, and a reset can discard the reply before it is read). With MAX_CONNECTIONS refusals already
        lingering, it is closed at once."""
        self.server.connections.discard(self)
        self._items.clear()
        self._input, self._at = b"", 0
        self.transport.write(encoded(GSProReply(Code=503, Message=message)))
        if len(self.server.refused) >= self.limits.max_connections:
            self.transport.close()
            return
        self.server.refused.add(self)
        self.transport.write_eof()
        self._ending = asyncio.get_running_loop().call_later(self.limits.linger_s, self.transport.abort)
        self._read(True)

    def work(self, deadline: float) -> None:
        """Frame and answer until `deadline` (`time.perf_counter`), the input is done, or the replies are left
        unread; then back in line, or reading again."""
        self._waiting = False
        while self._ending is None and self._writing and not self.transport.is_closing():
            if self._items:
                self._answer(self._items.popleft())
            elif self._at < len(self._input):
                piece = self._input[self._at : self._at + PIECE_BYTES]
                self._at += len(piece)
                if not self.bytes.take(len(piece)):
                    self.server.refuse(self, "a connector sent bytes too fast: closed", self.limits.too_many_bytes())
                    break
                self._items.extend(self.framer.feed(piece))
            else:
                break
            if time.perf_counter() >= deadline:
                break
        self._after_work()

    def _answer(self, item: bytes | Refused) -> None:
        if not self.messages.take():
            self.server.refuse(self, "a connector sent messages too fast: closed", self.limits.too_many_messages())
            return
        reply, valid = self.server.reply(item, self.client)
        if valid:
            self.last_message = time.monotonic()
        if reply is not None:
            self.transport.write(encoded(reply))

    def _backlog(self) -> bool:
        return bool(self._items) or self._at < len(self._input)

    def _after_work(self) -> None:
        """In line for the next turn (reading paused meanwhile), or, with nothing left, read again."""
        if self._ending is not None or self.transport.is_closing():
            return
        if self._backlog():
            self._read(False)
            if self._writing and not self._waiting:
                self._waiting = True
                self.server.wait_turn(self)
            return
        self._input, self._at = b"", 0
        self._read(self._writing)
        if self.framer.partial and not self.framer.stalled and self._pause is None:
            self._pause = asyncio.get_running_loop().call_later(PAUSE_S, self._stalled)

    def _stalled(self) -> None:
        self._pause = None
        self.framer.stall()

    def _read(self, on: bool) -> None:
        if on != self._reading:
            self._reading = on
            (self.transport.resume_reading if on else self.transport.pause_reading)()

    def _drop_unread(self) -> None:
        self.server.events.warning(f"a connector left its replies unread {self.limits.unread_limit_s:g} s: dropped")
        self._unread = None
        self.transport.abort()
