"""The runtime: NumPy physics, air and wind, integrators, the ONNX flight engine and the HTTP service (`service.api`)."""
