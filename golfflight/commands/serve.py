"""`golfflight serve`: the HTTP flight service (FastAPI on uvicorn) for a model bundle.

Binds 127.0.0.1 unless told otherwise. The API key comes from $GOLFFLIGHT_API_KEY only (never the command line,
where `ps` would show it); browser origins for CORS from --cors-origin or $GOLFFLIGHT_CORS_ORIGINS. The bundle is
verified completely before any worker starts; SIGTERM or Ctrl-C lets in-flight requests finish (up to
GRACEFUL_SHUTDOWN_S) before the workers exit. --connect-port also takes GSPro Open Connect over TCP in the same
process (`service.open_connect`), on loopback unless --connect-host says otherwise: the protocol has no key.
Several workers share their Prometheus metrics through files in $PROMETHEUS_MULTIPROC_DIR (a temporary directory
unless set), so GET /metrics answers for the whole server whichever worker takes the scrape. --bay FILE keeps the
simulator bay's conditions (air, wind, ground, player, units: GET/PUT/PATCH /v1/bay, `service.runtime.bay`) there
across restarts; a file that is not bay conditions stops the start with one line naming it and the field.
"""

from __future__ import annotations

import argparse
import copy
import errno
import importlib
import ipaddress
import socket
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from golfflight.commands import COMMANDS
from golfflight.errors import InputError

if TYPE_CHECKING:
    from golfflight.service.settings import ServiceSettings

GRACEFUL_SHUTDOWN_S = 30
"""Longest a shutdown waits for in-flight requests (a full 10,000-shot batch takes about a second)."""


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "serve", help=COMMANDS["serve"].summary
    )
    parser.add_argument("--host", default="127.0.0.1", help="interface to listen on (0.0.0.0 for every one)")
    parser.add_argument("--port", type=int, default=8000)
    parser.add_argument("--workers", type=int, default=1, help="processes, each with its own copy of the model")
    parser.add_argument("--model", help="model bundle directory (default: the shipped models/default)")
    parser.add_argument(
        "--cors-origin",
        action="append",
        metavar="ORIGIN",
        help="allow browser calls from this origin, e.g. https://sim.example.com (repeatable; default: CORS off)",
    )
    parser.add_argument(
        "--allowed-host",
        action="append",
        metavar="NAME",
        help="without an API key, also answer requests to this host name, e.g. bay-pc.local (repeatable; default: "
        "only localhost, 127.0.0.1, ::1 and the address listened on, so that no web page can reach the bay by DNS "
        "rebinding)",
    )
    parser.add_argument(
        "--connect-port",
        type=int,
        metavar="PORT",
        help="also take shots from launch-monitor connectors: GSPro Open Connect v1 over TCP on this port (GSPro's "
        "own is 921; below 1024 needs privileges on Linux)",
    )
    parser.add_argument(
        "--connect-host",
        help="interface for --connect-port (default 127.0.0.1; Open Connect has no authentication: keep loopback where "
        "you can)",
    )
    parser.add_argument(
        "--bay",
        metavar="FILE",
        help="the simulator bay's conditions (JSON: air, wind, ground, player, units as GET /v1/bay shows them): what "
        "Open Connect shots and shots without conditions of their own fly in; PUT and PATCH /v1/bay change them and "
        "write FILE (created if missing)",
    )
    parser.set_defaults(run=run)


def _loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _listenable(host: str, port: int, option: str) -> None:
    """Refuse a port that cannot be listened on now with one line saying why and naming the option that sets it, not
    a traceback at startup (or, for the HTTP port, after the line saying the service is up). The probe binds as uvicorn
    does (IPv6 when the host has a colon, SO_REUSEADDR), so a port it refuses is one uvicorn could not take either."""
    if not 0 < port < 65536:
        raise InputError(f"{option} must be 1 to 65535, got {port}")
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    try:
        socket.create_server((host, port), family=family).close()
    except OSError as error:
        if error.errno == errno.EADDRINUSE:
            raise InputError(
                f"{option}: {host}:{port} is in use (another program, perhaps another golfflight serve, listens "
                f"there): stop it or choose another port with {option}"
            ) from None
        raise InputError(f"{option}: cannot listen on {host}:{port}: {error.strerror or error}") from None


def fast_io() -> dict[str, object]:
    """uvicorn's event loop and HTTP protocol: uvloop (C, about 0.6 ms less per request than asyncio with h11:
    docs/benchmarks.md) where it is installed, asyncio otherwise (uvloop has no Windows build); and httptools (a
    dependency of the serving install) with deadlines for a request's head and body
    (`service.api.http_protocol`). Named, not left to uvicorn's "auto", so what serves is what was chosen."""
    from golfflight.service.api.http_protocol import DeadlineHttpProtocol

    try:
        importlib.import_module("uvloop")
    except ImportError:
        loop = "asyncio"
    else:
        loop = "uvloop"
    return {"loop": loop, "http": DeadlineHttpProtocol}


def logging_config() -> dict:
    """uvicorn's logging, plus golfflight's own loggers at INFO through uvicorn's handler: a bay's log says when a
    connector connects or leaves, when the bay file breaks or heals and when a limit refuses (each throttled where a
    hostile program could repeat it), in the same format as uvicorn's lines. Without this only warnings reached
    standard error, through Python's last-resort handler."""
    from uvicorn.config import LOGGING_CONFIG

    config = copy.deepcopy(LOGGING_CONFIG)
    config["loggers"]["golfflight"] = {"handlers": ["default"], "level": "INFO", "propagate": False}
    return config


def open_files_raised() -> int | None:
    """Raise this process's soft limit on open files to its hard limit (its workers inherit it) and return it; None
    where there is no such limit (Windows). Each connection is a file: under the common soft limit of 1,024, a
    program holding a thousand stalled requests left /healthz and the connector no descriptor to be answered on."""
    try:
        import resource
    except ImportError:
        return None
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    wanted = max(soft, 2**20) if hard == resource.RLIM_INFINITY else hard
    try:
        resource.setrlimit(resource.RLIMIT_NOFILE, (wanted, hard))
    except (ValueError, OSError):  # the system would not: serve under the limit there is
        return soft
    return wanted


FLAGS = {"model": "--model", "cors_origins": "--cors-origin", "allowed_hosts": "--allowed-host", "bay_file": "--bay",
         "connect_port": "--connect-port", "connect_host": "--connect-host"}
"""Each setting's flag: a flag given takes the place of the environment's value."""


def served_settings(args: argparse.Namespace, environment: ServiceSettings) -> ServiceSettings:
    """The service's settings: the flags given over the environment's, with the bundle found and made absolute and
    the bay file made absolute, so every worker reads the same ones. InputError naming the flag for a bad value."""
    from golfflight.flight.bundle_location import model_dir
    from golfflight.service.settings import ServiceSettings

    given = {field: getattr(args, flag[2:].replace("-", "_")) for field, flag in FLAGS.items()}
    given = {field: tuple(value) if isinstance(value, list) else value for field, value in given.items()
             if value is not None}
    values = {**environment.model_dump(), **given}
    values["model"] = model_dir(values["model"]).resolve()
    if values["bay_file"] is not None:
        values["bay_file"] = Path(values["bay_file"]).absolute()
    return ServiceSettings.validated(values, FLAGS)


def run(args: argparse.Namespace) -> int:
    import uvicorn

    from golfflight.flight.bundle_check import verify_bundle
    from golfflight.service.runtime.bay import Bay
    from golfflight.service.runtime.metrics import shared_across_workers
    from golfflight.service.settings import API_KEY_ENV, ServiceSettings

    if args.workers < 1:
        raise InputError(f"--workers must be at least 1, got {args.workers}")
    if args.connect_port is not None and args.workers != 1:
        raise InputError("--connect-port needs --workers 1 (one process holds the connectors' port)")
    settings = served_settings(args, ServiceSettings.from_env())  # the one reading of the environment
    card = verify_bundle(settings.model)  # refuse a bad bundle here, before any worker starts
    bay = Bay(settings.bay_file).conditions if settings.bay_file else None  # and a bad bay file
    _listenable(args.host, args.port, "--port")  # before the line saying it serves there
    connect = "off"
    if settings.connect_port is not None:
        _listenable(settings.connect_host, settings.connect_port, "--connect-port")
        connect = f"on tcp://{settings.connect_host}:{settings.connect_port}"
    keyed = bool(settings.api_key)
    print(
        f"golfflight serve: {card.variant} model from {settings.model} on http://{args.host}:{args.port} (docs at "
        f"/docs), {args.workers} worker(s), API key {'required' if keyed else 'off'}, "
        f"CORS {','.join(settings.cors_origins) or 'off'}, GSPro Open Connect {connect}"
        + (f", bay {settings.bay_file} ({bay.model_dump_json(exclude_none=True)})" if bay else "")
    )
    if not keyed and not _loopback(args.host):
        print(
            f"golfflight serve: warning: listening on {args.host} without an API key: anyone who can reach the port "
            f"can use the service (set {API_KEY_ENV})",
            file=sys.stderr,
        )
    if settings.connect_port is not None and not _loopback(settings.connect_host):
        print(
            f"golfflight serve: warning: GSPro Open Connect on {settings.connect_host}: anyone who can reach port "
            f"{settings.connect_port} can send shots (the protocol has no key)",
            file=sys.stderr,
        )
    open_files_raised()
    settings.hand_down()  # the factory in every worker process reads them
    with shared_across_workers(args.workers):  # GET /metrics sums every worker's counts
        uvicorn.run(
            "golfflight.service.app:create_app",
            factory=True,
            host=args.host,
            port=args.port,
            workers=args.workers,
            access_log=False,
            log_level="warning",
            log_config=logging_config(),
            timeout_graceful_shutdown=GRACEFUL_SHUTDOWN_S,
            **fast_io(),
        )
    return 0
