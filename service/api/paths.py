"""Paths the HTTP app's parts agree on without importing each other's routes."""

GSPRO_PATH = "/v1/gspro"
"""POST: a GSPro Open Connect message over HTTP; its refusals read as Open Connect's (`service.api.errors`)."""

SIMULATION_PATHS = frozenset({"/v1/shots", "/v1/shots/batch", GSPRO_PATH})
"""The routes whose requests are timed into /v1/latency's request window."""
