"""Load a model bundle directory (model_card.json + the ONNX file it names); refuse anything that does not check out."""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from golfflight.errors import InputError
from golfflight.weights_schema.model_card import SUPPORTED_SCHEMA_VERSIONS, ModelCard
from pydantic import ValidationError

CARD_FILE = "model_card.json"


class BundleError(InputError):
    """A bundle that must not be used; the message says which file and why."""


def sha256_of(path: str | os.PathLike) -> str:
    """SHA-256 of a file, lower-case hex."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def load_bundle(directory: str | os.PathLike) -> tuple[ModelCard, Path]:
    """(card, ONNX path) of a bundle, after checking: the card parses and validates, its schema version is one
    this code knows, and the ONNX file's SHA-256 is the one in the card."""
    directory = Path(directory)
    card_path = directory / CARD_FILE
    if not card_path.is_file():
        raise BundleError(f"{directory}: not a model bundle (no {CARD_FILE})")
    try:
        raw = json.loads(card_path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as error:
        raise BundleError(f"{card_path}: not valid JSON ({error})") from None
    version = raw.get("schema_version") if isinstance(raw, dict) else None
    if version not in SUPPORTED_SCHEMA_VERSIONS:
        raise BundleError(
            f"{card_path}: schema_version {version!r} is not one this golfflight reads "
            f"{list(SUPPORTED_SCHEMA_VERSIONS)}"
        )
    try:
        card = ModelCard.model_validate(raw)
    except ValidationError as error:
        problems = "; ".join(f"{'.'.join(str(p) for p in e['loc'])}: {e['msg']}" for e in error.errors()[:10])
        raise BundleError(f"{card_path}: invalid model card ({error.error_count()} problems): {problems}") from None
    onnx_path = directory / card.onnx.file
    if Path(card.onnx.file).name != card.onnx.file or not onnx_path.is_file():
        raise BundleError(f"{card_path}: ONNX file {card.onnx.file!r} missing from the bundle directory")
    actual = sha256_of(onnx_path)
    if actual != card.onnx.sha256:
        raise BundleError(
            f"{onnx_path}: SHA-256 {actual} does not match the card's {card.onnx.sha256}: "
            "the model file was changed or corrupted"
        )
    return card, onnx_path
