"""The TCP listener: one protocol object per connector connection, objects framed as they arrive, one reply per shot.

It runs on the HTTP service's event loop, opened and closed by the app's lifespan, not in a process of its own: the
model is loaded once, TCP shots count in /v1/latency with HTTP's, and whatever the app does with its shots sees
these too. Shots fly inline on the loop (no thread): one takes about half a millisecond, less than a hop to a
thread costs, and the replies measured with several connectors sending at once stay in milliseconds
(docs/service.md), against the 5 s after which a connector sends a shot again. Each connection is an
`asyncio.Protocol`: bytes are framed and answered in the callback that receives them, with no stream buffer, task
or wake-up between the socket and the reply (docs/benchmarks.md, issue 25).
"""

from __future__ import annotations

import asyncio
import logging
import os
from dataclasses import dataclass

from golfflight.contract.gspro import GSProReply
from golfflight.service.open_connect.framing import ObjectFramer, Refused
from golfflight.service.open_connect.replies import Answer, reply_to

CONNECT_HOST_ENV = "GOLFFLIGHT_CONNECT_HOST"
CONNECT_PORT_ENV = "GOLFFLIGHT_CONNECT_PORT"
PAUSE_S = 2.0
"""Silence after which a half-received object counts as paused (`ObjectFramer.stall`): a connector writes a message
in one go, so its pieces arrive within milliseconds. Nothing is refused at the pause: what comes next is either the
rest of the object (answered as usual) or a new object, and then the unfinished one gets one refusal before the new
one is read."""
INTERNAL_ERROR = "internal error while answering this message (the server log has the details)"

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ConnectAddress:
    """Where to listen for connectors: loopback unless told otherwise (the protocol has no authentication)."""

    port: int
    host: str = "127.0.0.1"

    @classmethod
    def from_env(cls) -> ConnectAddress | None:
        """The address `golfflight serve --connect-port` passes its workers, or None when TCP is off."""
        port = os.environ.get(CONNECT_PORT_ENV)
        if not port:
            return None
        return cls(int(port), os.environ.get(CONNECT_HOST_ENV) or cls.host)


class OpenConnectServer:
    """GSPro Open Connect v1 on a TCP port; `answer` flies each message that carries a shot."""

    def __init__(self, answer: Answer):
        self.answer = answer
        self._server: asyncio.Server | None = None
        self.connections: set[Connection] = set()  # open now; each leaves when its connector goes or at `close`

    async def start(self, address: ConnectAddress, *, listening: bool = True) -> None:
        """Take the port (OSError when it cannot be had) and accept connectors on it, or with `listening` False only
        take it, so that a port that cannot be had stops a startup early, until `listen`."""
        loop = asyncio.get_running_loop()
        self._server = await loop.create_server(
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
        """Stop listening and close every connection (replies already written still go out)."""
        self._server.close()
        for connection in list(self.connections):
            connection.close()
        await self._server.wait_closed()

    def reply(self, item: bytes | Refused) -> GSProReply | None:
        """`reply_to`, with any unexpected failure answered (and logged) instead of ending the connection."""
        try:
            return reply_to(item, self.answer)
        except Exception:
            log.exception("GSPro Open Connect: answering a message failed")
            return GSProReply(Code=500, Message=INTERNAL_ERROR)


class Connection(asyncio.Protocol):
    """One connector's connection: what arrives is framed and answered at once; a pause of PAUSE_S mid-object
    marks it stalled (`ObjectFramer.stall`). Reading pauses while the connector does not take its replies."""

    def __init__(self, server: OpenConnectServer):
        self.server = server
        self.framer = ObjectFramer()
        self.transport: asyncio.Transport | None = None
        self._pause: asyncio.TimerHandle | None = None

    def connection_made(self, transport: asyncio.Transport) -> None:
        self.transport = transport
        self.server.connections.add(self)

    def data_received(self, data: bytes) -> None:
        if self._pause is not None:
            self._pause.cancel()
            self._pause = None
        for item in self.framer.feed(data):
            reply = self.server.reply(item)
            if reply is not None:
                self.transport.write(reply.model_dump_json(exclude_none=True).encode())
        if self.framer.partial and not self.framer.stalled:
            self._pause = asyncio.get_running_loop().call_later(PAUSE_S, self.framer.stall)

    def pause_writing(self) -> None:
        self.transport.pause_reading()

    def resume_writing(self) -> None:
        self.transport.resume_reading()

    def connection_lost(self, error: Exception | None) -> None:
        if self._pause is not None:
            self._pause.cancel()
        self.server.connections.discard(self)

    def close(self) -> None:
        self.transport.close()
