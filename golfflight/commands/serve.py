"""`golfflight serve`: the HTTP flight service (FastAPI on uvicorn) for a model bundle."""

from __future__ import annotations

import argparse
import os


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser("serve", help="serve flights over HTTP (OpenAPI docs at /docs)")
    parser.add_argument("--host", default="127.0.0.1", help="interface to listen on (0.0.0.0 for every one)")
    parser.add_argument("--port", type=int, default=8000)
    parser.add_argument("--workers", type=int, default=1, help="processes, each with its own copy of the model")
    parser.add_argument("--model", help="model bundle directory (default: the shipped models/default)")
    parser.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import uvicorn

    from service.model_location import MODEL_ENV, model_dir
    from weights_schema.bundle import load_bundle

    bundle = model_dir(args.model).resolve()
    card, _ = load_bundle(bundle)  # refuse a bad bundle here, before any worker starts
    os.environ[MODEL_ENV] = str(bundle)  # the factory in every worker process reads it
    print(f"golfflight serve: {card.variant} model from {bundle} on http://{args.host}:{args.port} (docs at /docs)")
    uvicorn.run(
        "service.api.app:create_app",
        factory=True,
        host=args.host,
        port=args.port,
        workers=args.workers,
        access_log=False,
        log_level="warning",
    )
    return 0
