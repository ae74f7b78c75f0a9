"""Runtime flight engine: NumPy physics, air and wind, the integrator (and, later, the HTTP service)."""
