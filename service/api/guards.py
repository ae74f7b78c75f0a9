"""Pure ASGI guards in front of the routes: a request-body size limit, an optional API key, and without a key a
check of the Host header against the names the service answers to.

All answer before FastAPI parses anything, so an oversized, unauthenticated or misdirected request costs the worker
a few microseconds, not a JSON parse. None ever logs a header or the key.
"""

from __future__ import annotations

import hmac
import json

from golfflight.contract.refusals import body_detail
from golfflight.service.api.request_body import read_body, replay
from golfflight.service.settings import ALLOWED_HOSTS_ENV, API_KEY_ENV, CORS_ORIGINS_ENV

MAX_BODY_BYTES = 8 * 1024 * 1024
"""Largest request body accepted (a full 10,000-shot batch with every option is about 4.5 MB)."""

LOOPBACK_HOSTS = frozenset({"localhost", "127.0.0.1", "::1"})
"""Host names always answered: the machine itself."""

UNSAFE_METHODS = frozenset({"POST", "PUT", "PATCH", "DELETE"})
"""Methods that change something (a shot is flown and kept, a session started, the bay changed): refused from
another origin's web page without a key (`CrossSite`)."""

SIMPLE_TYPES = frozenset({b"", b"text/plain", b"application/x-www-form-urlencoded", b"multipart/form-data"})
"""Bodies a web page may send to another origin without asking it first (none at all, or these content types)."""

OPEN_PATHS = frozenset({"/healthz"})
"""Routes always answered without the API key (load balancers and health checks hold no secret); the assembly adds
the pages that hold no data (the viewer's, which asks for the key to open its event stream)."""


async def _send_json(send, status: int, body: dict, headers: list[tuple[bytes, bytes]] = ()) -> None:
    payload = json.dumps(body).encode()
    await send(
        {
            "type": "http.response.start",
            "status": status,
            "headers": [
                (b"content-type", b"application/json"),
                (b"content-length", str(len(payload)).encode()),
                *headers,
            ],
        }
    )
    await send({"type": "http.response.body", "body": payload})


class BodyLimit:
    """Refuses a request body over `limit` bytes with 413: at once from Content-Length, else (a chunked body) after
    reading at most `limit` bytes of it, which are then replayed to the app."""

    def __init__(self, app, limit: int = MAX_BODY_BYTES):
        self.app, self.limit = app, limit

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        declared = dict(scope["headers"]).get(b"content-length")
        if declared is not None:
            if not declared.isdigit() or int(declared) > self.limit:
                await self._refuse(send, declared.decode("latin-1"))
                return
            await self.app(scope, receive, send)
            return
        read = await read_body(receive, self.limit)
        if read is None:
            await self._refuse(send, f"over {self.limit:,}")
            return
        await self.app(scope, replay(read[0], receive), send)

    async def _refuse(self, send, size: str) -> None:
        message = f"request body of {size} bytes refused: the limit is {self.limit:,} bytes"
        await _send_json(send, 413, {"detail": [body_detail(message, "body_too_large")]})


class ApiKey:
    """Requires `X-API-Key: KEY` (or `Authorization: Bearer KEY`) on every route except OPEN_PATHS and `open_paths`;
    CORS preflight requests pass (they carry no credentials; the CORS middleware outside answers them)."""

    def __init__(self, app, key: str, open_paths: frozenset[str] = frozenset()):
        self.app, self._key, self._open = app, key.encode(), OPEN_PATHS | open_paths

    def _authorised(self, headers: dict[bytes, bytes]) -> bool:
        given = headers.get(b"x-api-key")
        if given is None:
            scheme, _, token = headers.get(b"authorization", b"").partition(b" ")
            given = token.strip() if scheme.lower() == b"bearer" else b""
        return hmac.compare_digest(given, self._key)

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http" or scope["path"] in self._open or scope["method"] == "OPTIONS":
            await self.app(scope, receive, send)
            return
        if self._authorised(dict(scope["headers"])):
            await self.app(scope, receive, send)
            return
        message = "missing or wrong API key: send it in the X-API-Key header (or Authorization: Bearer)"
        await _send_json(send, 401, {"detail": message}, [(b"www-authenticate", b'Bearer realm="golfflight"')])


def host_name(header: bytes) -> str:
    """The name in a Host header, lower case, without its port, its IPv6 brackets or a final dot."""
    text = header.decode("latin-1").strip().lower()
    if text.startswith("["):
        return text[1:].partition("]")[0]
    return text.rpartition(":")[0].rstrip(".") if text.count(":") == 1 else text.rstrip(".")


class HostCheck:
    """Without an API key, answers only requests whose Host names this machine: LOOPBACK_HOSTS, the address the
    request arrived on (the bound address, or the machine's address on the network when bound to 0.0.0.0) and
    `allowed`. DNS rebinding (a web page whose own name comes to point at 127.0.0.1) reaches the port from the
    browser of anyone at the bay PC, with that page's name as the Host: it is refused here, 403 before any route,
    so it can neither change the bay nor read the session. OPEN_PATHS and requests with no Host (no browser sends
    one without) pass. A request that changes something (`CrossSite`) must also come from no web page or from this
    service's own, `origins` or a page on an `allowed` name."""

    def __init__(self, app, allowed: frozenset[str] = frozenset(), origins: frozenset[str] = frozenset()):
        self.app = app
        self._allowed = LOOPBACK_HOSTS | {host_name(name.encode()) for name in allowed}
        self._cross_site = CrossSite(frozenset(host_name(name.encode()) for name in allowed), origins)

    def _answered(self, scope) -> bool:
        header = dict(scope["headers"]).get(b"host")
        if header is None or scope["path"] in OPEN_PATHS:
            return True
        name = host_name(header)
        server = scope.get("server")
        return name in self._allowed or (server is not None and name == str(server[0]).lower())

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        if not self._answered(scope):
            sent = _shown(dict(scope["headers"])[b"host"])
            message = (f"Host {sent!r} is not a name this golfflight answers to without an API key (this machine's: "
                       f"{', '.join(sorted(self._allowed))} or the address it listens on): add it to "
                       f"${ALLOWED_HOSTS_ENV} (serve --allowed-host), or set ${API_KEY_ENV}")
            await _send_json(send, 403, {"detail": message})
            return
        refusal = self._cross_site.refusal(scope)
        if refusal is not None:
            await _send_json(send, 403, {"detail": refusal})
            return
        await self.app(scope, receive, send)


class CrossSite:
    """Refuses a request that changes something (UNSAFE_METHODS) sent by a web page of another origin without
    asking first: a page anywhere can make a visitor's browser POST to the bay with no body, a form's body or plain
    text (a form, or `fetch` in no-cors mode: no CORS permission is asked for these, SIMPLE_TYPES) and, without a
    key, start empty sessions or change the bay. Browsers name the page's origin in an `Origin` header on every
    request that is not a GET or HEAD (`null` for a page without one). A request without it comes from no browser
    page and passes, as does one from this service's own origin (the viewer), from `origins` (CORS) or from a page
    on one of `names` (serve --allowed-host), and one with a JSON body (a browser sends it only once CORS allowed)."""

    def __init__(self, names: frozenset[str], origins: frozenset[str]):
        self._names = names
        self._origins = frozenset(origin.rstrip("/").lower() for origin in origins)

    def _own(self, origin: bytes, host: bytes | None) -> bool:
        """Whether the page of `origin` is this service's own (the Host asked for), one of `origins` or on `names`."""
        text = origin.decode("latin-1").strip().lower().rstrip("/")
        if text in self._origins:
            return True
        _, separator, place = text.partition("://")
        if not separator:  # "null": a sandboxed page, a file, a page whose referrer policy hides it
            return False
        same = host is not None and place == host.decode("latin-1").strip().lower()
        return same or host_name(place.encode("latin-1")) in self._names

    def refusal(self, scope) -> str | None:
        """Why this request is refused, or None when it may go on."""
        if scope["method"] not in UNSAFE_METHODS:
            return None
        headers = dict(scope["headers"])
        origin = headers.get(b"origin")
        media_type = headers.get(b"content-type", b"").partition(b";")[0].strip().lower()
        if origin is None or media_type not in SIMPLE_TYPES or self._own(origin, headers.get(b"host")):
            return None
        return (f"{scope['method']} from the web page of another origin ({_shown(origin)!r}) without a JSON body "
                f"(content-type application/json) refused: without an API key, only this service's own pages, the "
                f"origins of ${CORS_ORIGINS_ENV} (serve --cors-origin) and pages on ${ALLOWED_HOSTS_ENV} names may "
                f"change the bay or its sessions that way; or set ${API_KEY_ENV}")


def _shown(header: bytes) -> str:
    """A Host header as a refusal quotes it: cut to 80 characters."""
    return header.decode("latin-1")[:80]
