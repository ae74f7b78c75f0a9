"""The ground floor: the physics of a golf ball in flight, the one batch integrator every NumPy flight goes through,
and the one `Flyer` that finds a model bundle and flies shots through it (`flight.flyer`). Depends on nothing of ours
but `weights_schema`; `shots`, `model_export`, `discovery` and `service` stand on it."""
