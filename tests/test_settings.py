"""The service's one settings object: read once from the GOLFFLIGHT_* variables (or whole, as `serve` hands it to its
workers), flags over the environment, a bad value refused naming its variable or flag (that no other module reads
the environment: tests/test_environment.py)."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest
from golfflight.commands.serve import register, served_settings
from golfflight.errors import InputError
from golfflight.flight.bundle_location import CHECKOUT_MODEL
from golfflight.flight.environment_variables import VARIABLES
from golfflight.service.settings import HANDED_DOWN_ENV, ServiceSettings

ENVIRONMENT = {
    "GOLFFLIGHT_API_KEY": "secret",
    "GOLFFLIGHT_CORS_ORIGINS": "https://sim.example, https://bay.example,",
    "GOLFFLIGHT_ALLOWED_HOSTS": "bay-pc.local",
    "GOLFFLIGHT_BAY_FILE": "/srv/bay.json",
    "GOLFFLIGHT_CONNECT_PORT": "921",
    "GOLFFLIGHT_CONNECT_HOST": "0.0.0.0",
}


def environment_of(monkeypatch: pytest.MonkeyPatch, variables: dict[str, str]) -> None:
    """This process's environment holding `variables` and no other of golfflight's (restored after the test)."""
    for name in VARIABLES:
        monkeypatch.delenv(name, raising=False)
    for name, value in variables.items():
        monkeypatch.setenv(name, value)


def test_each_variable_gives_its_setting(monkeypatch):
    environment_of(monkeypatch, ENVIRONMENT)
    settings = ServiceSettings.from_env()
    assert settings == ServiceSettings(api_key="secret", cors_origins=("https://sim.example", "https://bay.example"),
                                       allowed_hosts=("bay-pc.local",), bay_file=Path("/srv/bay.json"),
                                       connect_port=921, connect_host="0.0.0.0")
    assert "secret" not in repr(settings)


def test_unset_or_empty_variables_leave_the_defaults(monkeypatch):
    environment_of(monkeypatch, {})
    assert ServiceSettings.from_env() == ServiceSettings()
    environment_of(monkeypatch, {name: "" for name in ENVIRONMENT})
    assert ServiceSettings.from_env() == ServiceSettings()
    assert ServiceSettings().connect_port is None and ServiceSettings().connect_host == "127.0.0.1"


@pytest.mark.parametrize("port", ["0", "70000", "nine"])
def test_a_bad_value_is_refused_naming_its_variable(monkeypatch, port):
    environment_of(monkeypatch, {"GOLFFLIGHT_CONNECT_PORT": port})
    with pytest.raises(InputError, match=rf"^\$GOLFFLIGHT_CONNECT_PORT: .* \(got '{port}'\); allowed 1 to 65535$"):
        ServiceSettings.from_env()


def test_handed_down_settings_are_read_back_whole(monkeypatch):
    settings = ServiceSettings(api_key="k", cors_origins=("https://a.example",), connect_port=9210, model=Path("/m"))
    environment_of(monkeypatch, {HANDED_DOWN_ENV: "", "GOLFFLIGHT_API_KEY": "x"})  # restored after the test
    settings.hand_down()
    assert ServiceSettings.from_env() == settings


def _serve_args(*flags: str) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    register(parser.add_subparsers())
    return parser.parse_args(["serve", *flags])


def test_serve_puts_its_flags_over_the_environment(monkeypatch, tmp_path):
    environment_of(monkeypatch, ENVIRONMENT)
    monkeypatch.chdir(tmp_path)
    environment = ServiceSettings.from_env()
    settings = served_settings(_serve_args("--cors-origin", "https://c.example", "--bay", "bay.json",
                                           "--connect-port", "9921"), environment)
    assert settings.cors_origins == ("https://c.example",) and settings.connect_port == 9921
    assert settings.bay_file == tmp_path / "bay.json" and settings.model == CHECKOUT_MODEL.resolve()
    assert (settings.api_key, settings.allowed_hosts, settings.connect_host) == ("secret", ("bay-pc.local",), "0.0.0.0")
    assert served_settings(_serve_args(), environment).bay_file == Path("/srv/bay.json")


def test_serve_refuses_a_bad_flag_naming_it():
    with pytest.raises(InputError, match=r"^--connect-port: .*65535 \(got 70000\); allowed 1 to 65535$"):
        served_settings(_serve_args("--connect-port", "70000"), ServiceSettings())
