"""`python -m golfflight.service.viewer`: regenerate event.schema.json from the pydantic models."""

from golfflight.service.viewer.event import SCHEMA_PATH, schema_text

SCHEMA_PATH.write_text(schema_text())
print(f"wrote {SCHEMA_PATH}")
