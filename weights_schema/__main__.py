"""`python -m golfflight.weights_schema`: regenerate model_card.schema.json from the pydantic models."""

from golfflight.weights_schema.model_card import write_schema

print(f"wrote {write_schema()}")
