"""The service's settings, one object read once: `golfflight serve` builds it from its flags over the environment,
checks it, and hands it whole to every worker process; `create_app` takes it and passes each part down (the API key
to the HTTP guards, the bay file to the runtime, the connect address to Open Connect). The variables are read by
`flight.environment_variables.Environment`, the one pydantic-settings object that reads the environment: each setting
`field` from GOLFFLIGHT_FIELD (its prefix), the bundle's own $GOLFFLIGHT_MODEL where every command finds its bundle
(`flight.bundle_location.model_dir`)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from golfflight.errors import InputError
from golfflight.flight.environment_variables import (
    SERVICE_FIELDS, SERVICE_SETTINGS, environment, set_for_children, variable_of
)
from pydantic import BaseModel, ConfigDict, Field, ValidationError

HANDED_DOWN_ENV = SERVICE_SETTINGS
"""How `serve` hands the settings to uvicorn's worker processes, which import the app's factory by name and so take no
arguments: the whole object as JSON in one variable, read back whole (`ServiceSettings.from_env`)."""

API_KEY_ENV = variable_of("api_key")
CORS_ORIGINS_ENV = variable_of("cors_origins")
ALLOWED_HOSTS_ENV = variable_of("allowed_hosts")
"""The variables that messages name (`serve`'s warning, the guards' refusals)."""


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
    def from_env(cls) -> ServiceSettings:
        """The settings a worker was handed (HANDED_DOWN_ENV), else those the GOLFFLIGHT_* variables give (unset or
        empty: the default); InputError naming the variable for a value out of range."""
        read = environment()
        if read.service_settings:
            return cls.model_validate_json(read.service_settings)
        given = read.model_dump(include=set(SERVICE_FIELDS), exclude_none=True)
        return cls.validated(given, {field: f"${variable_of(field)}" for field in SERVICE_FIELDS})

    @classmethod
    def validated(cls, values: Mapping[str, object], names: Mapping[str, str]) -> ServiceSettings:
        """The settings `values` give; InputError naming a refused setting as it was given (`names`: its variable or
        its flag), with the value given and the range the setting allows, where it has one."""
        try:
            return cls.model_validate(values)
        except ValidationError as error:
            problem = error.errors()[0]
            field = problem["loc"][0]
            raise InputError(problem["msg"], field=names.get(field, field), value=values[field],
                             allowed=_range_of(field)) from None

    def hand_down(self) -> None:
        """Put these settings where the worker processes about to start will read them (`from_env`)."""
        set_for_children(HANDED_DOWN_ENV, self.model_dump_json())


def _range_of(field: str) -> str | None:
    """'LOW to HIGH' of a setting bounded both ways (the port: 1 to 65535), read from its Field; None otherwise."""
    bounds = {name: getattr(rule, name) for rule in ServiceSettings.model_fields[field].metadata
              for name in ("ge", "le") if hasattr(rule, name)}
    return f"{bounds['ge']} to {bounds['le']}" if len(bounds) == 2 else None
