"""Pure ASGI middleware timing every HTTP request once, for /metrics and /v1/latency alike.

It sits outside every other middleware, so requests the guards refuse (401, 413) are counted too. Labels stay
bounded whatever clients send: the route's template (`/viewer/{name}`, never the raw path; `<unmatched>` for a path
no route has) and the method among the standard ones (`other` for the rest).
"""

from __future__ import annotations

import time

from golfflight.service.runtime.latency import Rolling
from golfflight.service.runtime.metrics import ServiceMetrics
from starlette.routing import BaseRoute, Match

UNMATCHED = "<unmatched>"
"""Route label of a request whose path no route serves (a 404)."""

METHODS = frozenset({"GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS"})
"""Method labels kept as sent; any other method is labelled `other`."""


def route_template(routes: list[BaseRoute], scope: dict, path: tuple[str, str] | None = None) -> str:
    """The path template of the route that serves `scope`: the one the router chose, or, for a request answered
    before routing (a guard's refusal) or by a mount (whose scope the router leaves without a route, its path
    rebased), the first of `routes` (every route of the app, each with its whole path) that matches `path`, the
    request's (path, root_path) as it came in."""
    chosen = getattr(scope.get("route"), "path", None)
    if chosen is not None:
        return chosen
    if path is not None:
        scope = {**scope, "path": path[0], "root_path": path[1]}
    for route in routes:
        match, _ = route.matches(scope)
        if match is not Match.NONE:
            return route.path
    return UNMATCHED


class RequestMetrics:
    """Counts and times every HTTP request by route template, method and status; the requests on `timed_routes`
    (the simulation routes, each with its kind) also go to `rolling[kind]`, /v1/latency's request windows."""

    def __init__(self, app, metrics: ServiceMetrics, routes: list[BaseRoute], rolling: dict[str, Rolling],
                 timed_routes: dict[str, str]):
        self.app, self.metrics, self.routes = app, metrics, routes
        self.timed = {route: rolling[kind] for route, kind in timed_routes.items()}
        self._series: dict[tuple[str, str, int], tuple] = {}

    def _series_of(self, route: str, method: str, status: int) -> tuple:
        """The (request counter, duration histogram) of one label set, looked up in prometheus-client once and kept:
        a bounded set (route templates x standard methods x statuses), so no per-request label lookup."""
        key = (route, method, status)
        series = self._series.get(key)
        if series is None:
            series = (self.metrics.requests.labels(route, method, str(status)),
                      self.metrics.request_seconds.labels(route, method))
            self._series[key] = series
        return series

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        status = 500  # what the client gets if the app raises before it answers

        async def send_and_note_status(message):
            nonlocal status
            if message["type"] == "http.response.start":
                status = message["status"]
            await send(message)

        path = scope["path"], scope.get("root_path", "")  # a mount rebases the scope's own
        started = time.perf_counter()
        try:
            await self.app(scope, receive, send_and_note_status)
        finally:
            seconds = time.perf_counter() - started
            route = route_template(self.routes, scope, path)
            method = scope["method"] if scope["method"] in METHODS else "other"
            requests, durations = self._series_of(route, method, status)
            requests.inc()
            durations.observe(seconds)
            window = self.timed.get(route)
            if window is not None:
                window.add(seconds)
