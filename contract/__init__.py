"""The shot contract: what a shot request says, how it becomes the engine's launch, conditions and ground, and what
comes back, in every form a caller reads it (HTTP, GSPro Open Connect, the viewer, the command line, sweep columns).
Pydantic and plain functions only: no HTTP wiring, which lives in `service.api`."""
