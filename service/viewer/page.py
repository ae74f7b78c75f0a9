"""The viewer page and its script and style, shipped in `static/` (package data) and read once at import."""

from __future__ import annotations

from importlib.resources import files

PAGE_PATH = "/viewer"

ASSETS: dict[str, tuple[bytes, str]] = {
    name: (files(__package__).joinpath("static", name).read_bytes(), media_type)
    for name, media_type in (
        ("viewer.html", "text/html; charset=utf-8"),
        ("viewer.js", "text/javascript; charset=utf-8"),
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
