"""The service's settings, one object read once: `golfflight serve` builds it from its flags over the environment,
checks it, and hands it whole to every worker process; `create_app` takes it and passes each part down (the API key
to the HTTP guards, the bay file to the runtime, the connect address to Open Connect). Nothing else of the service
reads the environment for a setting. The bundle's own variable, $GOLFFLIGHT_MODEL, is read where every command finds
its bundle (`flight.bundle_location.model_dir`)."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

from golfflight.errors import InputError
from pydantic import BaseModel, ConfigDict, Field, ValidationError

HANDED_DOWN_ENV = "GOLFFLIGHT_SERVICE_SETTINGS"
"""How `serve` hands the settings to uvicorn's worker processes, which import the app's factory by name and so take no
arguments: the whole object as JSON in one variable, read back whole (`ServiceSettings.from_env`)."""

API_KEY_ENV = "GOLFFLIGHT_API_KEY"
CORS_ORIGINS_ENV = "GOLFFLIGHT_CORS_ORIGINS"
ALLOWED_HOSTS_ENV = "GOLFFLIGHT_ALLOWED_HOSTS"
BAY_FILE_ENV = "GOLFFLIGHT_BAY_FILE"
CONNECT_PORT_ENV = "GOLFFLIGHT_CONNECT_PORT"
CONNECT_HOST_ENV = "GOLFFLIGHT_CONNECT_HOST"

VARIABLES = {
    API_KEY_ENV: "api_key",
    CORS_ORIGINS_ENV: "cors_origins",
    ALLOWED_HOSTS_ENV: "allowed_hosts",
    BAY_FILE_ENV: "bay_file",
    CONNECT_PORT_ENV: "connect_port",
    CONNECT_HOST_ENV: "connect_host",
}
"""Each environment variable and the setting it gives; a list is comma-separated."""

LISTS = frozenset({"cors_origins", "allowed_hosts"})


def listed(text: str) -> tuple[str, ...]:
    """The items of a comma-separated setting (origins, host names), blanks left out."""
    return tuple(item.strip() for item in text.split(",") if item.strip())


class ServiceSettings(BaseModel):
    """What a served bay is told: its model, who may call it, where its bay file is and whether GSPro connectors
    reach it over TCP."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    model: Path | None = Field(None, description="the bundle; None: `flight.bundle_location.model_dir()`'s default")
    api_key: str = Field("", repr=False, description="when set, every route but /healthz and the viewer's page needs it")
    cors_origins: tuple[str, ...] = Field((), description="browser origins allowed to call the service; none: CORS off")
    allowed_hosts: tuple[str, ...] = Field((), description="Host names answered without an API key, beyond loopback")
    bay_file: Path | None = Field(None, description="where the bay's conditions are kept; None: in memory only")
    connect_port: int | None = Field(None, ge=1, le=65535, description="GSPro Open Connect over TCP; None: off")
    connect_host: str = Field("127.0.0.1", min_length=1, description="the address Open Connect listens on")

    @classmethod
    def from_env(cls, environ: Mapping[str, str] = os.environ) -> ServiceSettings:
        """The settings a worker was handed (HANDED_DOWN_ENV), else those the GOLFFLIGHT_* variables give (unset or
        empty: the default); InputError naming the variable for a value out of range."""
        handed = environ.get(HANDED_DOWN_ENV)
        if handed:
            return cls.model_validate_json(handed)
        given = {name: environ[name] for name in VARIABLES if environ.get(name)}
        values = {VARIABLES[name]: listed(text) if VARIABLES[name] in LISTS else text for name, text in given.items()}
        try:
            return cls(**values)
        except ValidationError as error:
            problem = error.errors()[0]
            name = next(n for n, field in VARIABLES.items() if field == problem["loc"][0])
            raise InputError(f"${name}: {problem['msg']}, got {given[name]!r}") from None

    def hand_down(self) -> None:
        """Put these settings where the worker processes about to start will read them (`from_env`)."""
        os.environ[HANDED_DOWN_ENV] = self.model_dump_json()
