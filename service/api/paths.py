"""Paths the HTTP app's parts agree on without importing each other's routes."""

GSPRO_PATH = "/v1/gspro"
"""POST: a GSPro Open Connect message over HTTP; its refusals read as Open Connect's (`service.api.errors`)."""

SIMULATION_PATHS = {"/v1/shots": "shot", GSPRO_PATH: "shot", "/v1/shots/batch": "batch"}
"""The routes whose requests are timed into /v1/latency's request windows, each with its window's kind (single shots
and batches apart, `service.runtime.latency.KINDS`)."""
