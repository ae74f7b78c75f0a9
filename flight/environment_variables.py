"""The one module that reads the process's environment, and sets what golfflight hands to the worker processes it
starts: every variable is a field of one pydantic-settings object (`Environment`), ours under one prefix
(GOLFFLIGHT_), and listed in docs/service.md's table of them. It sits in the flight core, the lowest floor that reads
one (where the bundle is), so every floor above reads through it; tests/test_environment.py fails on any other module
that reads os.environ."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Annotated

from pydantic import Field, field_validator
from pydantic_settings import BaseSettings, NoDecode, SettingsConfigDict

PREFIX = "GOLFFLIGHT_"
"""Every variable of ours starts so: a field `name` of `Environment` is read from PREFIX + NAME (pydantic-settings'
`env_prefix`), unless the field names a library's own variable (`validation_alias`)."""

Listed = Annotated[tuple[str, ...], NoDecode]
"""A comma-separated setting (origins, host names), read as text and split by `Environment._split`, not as JSON."""


class Environment(BaseSettings):
    """Every environment variable golfflight reads, read when built (`environment()`): unset or empty gives the
    default. The service's port stays text here, checked by the one command that needs it (`serve`, naming the
    variable: `service.settings.ServiceSettings.from_env`), so that a bad one stops no other command."""

    model_config = SettingsConfigDict(env_prefix=PREFIX, env_ignore_empty=True, extra="ignore", frozen=True)

    model: Path | None = Field(None, description="the bundle (flight.bundle_location)")
    shared_data: Path | None = Field(None, description="the shared data folder (shots.paths)")
    api_key: str = Field("", repr=False, description="the service's API key (service.settings)")
    cors_origins: Listed = Field((), description="browser origins, comma-separated (service.settings)")
    allowed_hosts: Listed = Field((), description="Host names answered without a key (service.settings)")
    bay_file: Path | None = Field(None, description="the bay file (service.settings)")
    connect_port: str | None = Field(None, description="the Open Connect port, as given (service.settings)")
    connect_host: str | None = Field(None, description="the Open Connect interface (service.settings)")
    service_settings: str | None = Field(None, description="the settings `serve` hands its workers, JSON")
    metrics_dir: Path | None = Field(
        None, validation_alias="PROMETHEUS_MULTIPROC_DIR",
        description="prometheus-client's own name: it reads the variable itself in every worker, so the name cannot "
        "take our prefix (service.runtime.metrics)",
    )
    ray_data_log_level: str | None = Field(
        None, validation_alias="RAY_DATA_LOG_LEVEL",
        description="Ray Data's own name, read by Ray itself; a sweep only leaves Ray's log level alone when it is set "
        "(sweep.engines)",
    )

    @field_validator("cors_origins", "allowed_hosts", mode="before")
    @classmethod
    def _split(cls, text: object) -> object:
        """A comma-separated setting's items, blanks left out."""
        return tuple(item.strip() for item in text.split(",") if item.strip()) if isinstance(text, str) else text


SERVICE_FIELDS = ("api_key", "cors_origins", "allowed_hosts", "bay_file", "connect_port", "connect_host")
"""The service's settings read from the environment (`service.settings.ServiceSettings`)."""


def variable_of(field: str) -> str:
    """The variable a field of `Environment` is read from: its alias, else PREFIX + its name in capitals
    (`api_key`: GOLFFLIGHT_API_KEY)."""
    alias = Environment.model_fields[field].validation_alias
    return alias if isinstance(alias, str) else PREFIX + field.upper()


VARIABLES = tuple(variable_of(field) for field in Environment.model_fields)
"""Every variable golfflight reads."""

MODEL = variable_of("model")
SERVICE_SETTINGS = variable_of("service_settings")
METRICS_DIR = variable_of("metrics_dir")
"""The variables other modules name (a message, a hand-down, a library's switch)."""


def environment() -> Environment:
    """The variables as the process's environment holds them now (read anew each call: `set_for_children` and a
    test's changes show)."""
    return Environment()


def set_for_children(name: str, value: str | None) -> None:
    """Set a declared variable for the processes this one starts from now on (they inherit the environment); None
    removes it. KeyError for a name not in VARIABLES."""
    if name not in VARIABLES:
        raise KeyError(f"{name} is not one of golfflight's environment variables (flight.environment_variables)")
    if value is None:
        os.environ.pop(name, None)
    else:
        os.environ[name] = value
