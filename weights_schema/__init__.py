"""The model bundle contract (model.onnx + model_card.json): the card's pydantic schema and the bundle loader.

Pure pydantic + hashlib: the serving install imports this without torch.
"""

from golfflight.weights_schema.bundle import BundleError, load_bundle
from golfflight.weights_schema.model_card import SCHEMA_VERSION, ModelCard

__all__ = ["SCHEMA_VERSION", "BundleError", "ModelCard", "load_bundle"]
