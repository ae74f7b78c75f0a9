"""The one module that reads the process's environment, and sets what golfflight hands to the worker processes it
starts: each variable is declared here once, ours under one prefix (GOLFFLIGHT_), and listed in docs/service.md's
table of them. It sits in the flight core, the lowest floor that reads one (where the bundle is), so every floor
above reads through it; tests/test_environment.py fails on any other module that reads os.environ."""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping

PREFIX = "GOLFFLIGHT_"
"""Every variable of ours starts so; a setting `field` of the service is read from PREFIX + FIELD (`variable_of`)."""

MODEL = "GOLFFLIGHT_MODEL"
SHARED_DATA = "GOLFFLIGHT_SHARED_DATA"
SERVICE_SETTINGS = "GOLFFLIGHT_SERVICE_SETTINGS"
METRICS_DIR = "PROMETHEUS_MULTIPROC_DIR"
"""prometheus-client's own name: it reads the variable itself in every worker, so the name cannot take our prefix."""
RAY_DATA_LOG_LEVEL = "RAY_DATA_LOG_LEVEL"
"""Ray Data's own name, read by Ray itself; a sweep only leaves Ray's log level alone when it is set."""

SERVICE_FIELDS = ("api_key", "cors_origins", "allowed_hosts", "bay_file", "connect_port", "connect_host")
"""The service's settings read from the environment, each from PREFIX + its name in capitals
(`service.settings.ServiceSettings`)."""


def variable_of(field: str) -> str:
    """The variable a setting is read from: PREFIX + its name in capitals (`api_key`: GOLFFLIGHT_API_KEY)."""
    return PREFIX + field.upper()


VARIABLES = {
    MODEL: "flight.bundle_location",
    SHARED_DATA: "shots.paths",
    **{variable_of(field): "service.settings" for field in SERVICE_FIELDS},
    SERVICE_SETTINGS: "service.settings",
    METRICS_DIR: "service.runtime.metrics",
    RAY_DATA_LOG_LEVEL: "sweep.engines",
}
"""Every variable golfflight reads, and the module that reads it through this one."""


def given(name: str, environ: Mapping[str, str] | None = None) -> str | None:
    """A declared variable's value in `environ` (default: this process's environment); None where it is unset or
    empty (`NAME=` turns a setting off, as unset does). KeyError for a name not declared in VARIABLES."""
    return (os.environ if environ is None else environ).get(_declared(name)) or None


def prefixed(fields: Iterable[str], environ: Mapping[str, str] | None = None) -> dict[str, str]:
    """The fields whose variable (PREFIX + FIELD) is set and not empty, with its text: what pydantic-settings'
    `env_prefix` reads, without the dependency."""
    texts = {field: given(variable_of(field), environ) for field in fields}
    return {field: text for field, text in texts.items() if text is not None}


def set_for_children(name: str, value: str | None) -> None:
    """Set a declared variable for the processes this one starts from now on (they inherit the environment); None
    removes it."""
    if value is None:
        os.environ.pop(_declared(name), None)
    else:
        os.environ[_declared(name)] = value


def _declared(name: str) -> str:
    if name not in VARIABLES:
        raise KeyError(f"{name} is not one of golfflight's environment variables (flight.environment_variables)")
    return name
