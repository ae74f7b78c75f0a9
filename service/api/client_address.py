"""The address a request came from, as uvicorn gives it: what a shot's share of the session memory is counted by."""

from __future__ import annotations

from fastapi import Request


def client_address(request: Request) -> str:
    """The client's host (`X-Forwarded-For` is believed only from uvicorn's trusted proxies: 127.0.0.1 by default),
    or "" where the server does not say."""
    return request.client.host if request.client else ""
