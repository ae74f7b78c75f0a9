"""Turns of the event loop handed out one at a time to the tasks that share them (the session downloads): however many
such tasks run, the loop runs one slice of their work per turn, between two rounds of everything else (shots).

A lock would not do: a slice has no `await` inside, so no task ever waits on the lock, and 50 downloads ran 50
slices in each turn of the loop (single shots waited 100-200 ms, issue 55)."""

from __future__ import annotations

import asyncio
from collections import deque


class LoopTurns:
    """First come, first served: a task awaits `turn()` before each slice of its work; one waiting task is let go
    per turn of the event loop."""

    def __init__(self) -> None:
        self._waiting: deque[asyncio.Future[None]] = deque()
        self._handing_out = False

    async def turn(self) -> None:
        """Return at this task's turn (a later turn of the loop than this one)."""
        loop = asyncio.get_running_loop()
        future = loop.create_future()
        self._waiting.append(future)
        if not self._handing_out:
            self._handing_out = True
            loop.call_soon(self._next, loop)
        await future

    def _next(self, loop: asyncio.AbstractEventLoop) -> None:
        """Let the first task still waiting go, and come back at the next turn of the loop while any waits."""
        while self._waiting:
            future = self._waiting.popleft()
            if not future.done():  # a cancelled task's (its client gone) is passed over
                future.set_result(None)
                break
        if self._waiting:
            loop.call_soon(self._next, loop)
        else:
            self._handing_out = False
