"""The ground floor: the physics of a golf ball in flight and the one batch integrator every NumPy flight goes
through. Depends on nothing of ours but `weights_schema`; `shots`, `model_export`, `discovery` and `service` stand
on it."""
