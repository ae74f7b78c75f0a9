"""The viewer page, its scripts (`viewer.js`; `session.js`: the session's events, summary and "New session") and
style, shipped in `static/` (package data) and read once at import; the page's club menu is filled in from GSPro's
club codes (`contract.clubs.GSPRO_CLUBS`: the value a code, the label its name), the clubs the bay's player can select
(`PATCH /v1/bay {"player": {"club": CODE}}`) and each shot's event names, and the bay form's ground menu from the
surfaces a request may name (`flight.ground.SURFACES`)."""

from __future__ import annotations

from html import escape
from importlib.resources import files

from golfflight.contract.clubs import GSPRO_CLUBS
from golfflight.flight.ground import SURFACES

PAGE_PATH = "/viewer"

CLUB_OPTIONS_MARKER = b"<!-- club options: contract.clubs.GSPRO_CLUBS, filled in by service/viewer/page.py -->"


def with_club_options(page: bytes) -> bytes:
    """The page with its club menu's options, one per GSPro club code in the bag's order: the code the value, the
    club's name the label."""
    if page.count(CLUB_OPTIONS_MARKER) != 1:
        raise RuntimeError("viewer.html has lost its club options marker")
    options = "".join(
        f'<option value="{escape(code)}">{escape(name)}</option>' for code, name in GSPRO_CLUBS.items()
    ).encode()
    return page.replace(CLUB_OPTIONS_MARKER, options)


SURFACE_OPTIONS_MARKER = b"<!-- surface options: flight.ground.SURFACES, filled in by service/viewer/page.py -->"


def with_surface_options(page: bytes) -> bytes:
    """The page with the bay form's ground menu: one option per surface a shot (and the bay) can name."""
    if page.count(SURFACE_OPTIONS_MARKER) != 1:
        raise RuntimeError("viewer.html has lost its surface options marker")
    options = "".join(
        f'<option value="{escape(name)}">{escape(name.replace("_", " "))}</option>' for name in SURFACES
    ).encode()
    return page.replace(SURFACE_OPTIONS_MARKER, options)


def _read(name: str) -> bytes:
    content = files(__package__).joinpath("static", name).read_bytes()
    return with_surface_options(with_club_options(content)) if name == "viewer.html" else content


ASSETS: dict[str, tuple[bytes, str]] = {
    name: (_read(name), media_type)
    for name, media_type in (
        ("viewer.html", "text/html; charset=utf-8"),
        ("viewer.js", "text/javascript; charset=utf-8"),
        ("session.js", "text/javascript; charset=utf-8"),
        ("viewer.css", "text/css; charset=utf-8"),
    )
}
"""File name -> (content, media type): the only files the viewer routes serve."""

PUBLIC_PATHS = frozenset({PAGE_PATH, *(f"{PAGE_PATH}/{name}" for name in ASSETS if name != "viewer.html")})
"""Served without the API key: the page holds no data; it asks for the key to open the event stream."""

SECURITY_HEADERS = {
    "content-security-policy": "default-src 'self'; img-src 'self' data:; base-uri 'none'; frame-ancestors 'none'",
    "cache-control": "no-cache",
    "x-content-type-options": "nosniff",
}
"""The page may load and fetch from the service itself only: nothing from the internet, even by mistake."""
