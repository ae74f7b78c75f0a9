"""An HTTP request's body read whole in pure ASGI middleware, and its messages given again to the app behind it."""

from __future__ import annotations


async def read_body(receive, limit: int | None = None) -> tuple[list[dict], bytes] | None:
    """(the messages received, the body they carry), or None once the body passes `limit` bytes (read no further)."""
    messages, chunks, received = [], [], 0
    while True:
        message = await receive()
        messages.append(message)
        if message["type"] != "http.request":
            break
        chunks.append(message.get("body", b""))
        received += len(chunks[-1])
        if limit is not None and received > limit:
            return None
        if not message.get("more_body", False):
            break
    return messages, b"".join(chunks)


def replay(messages: list[dict], receive):
    """A `receive` that gives `messages` again, then whatever comes next."""
    pending = list(messages)

    async def replayed():
        return pending.pop(0) if pending else await receive()

    return replayed
