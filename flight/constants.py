"""Physical constants of the ball and the simulation, SI units (the values every model shares)."""

BALL_MASS_KG = 0.04593
"""Maximum mass allowed by the Rules of Golf (1.620 oz)."""

BALL_RADIUS_M = 0.021335
"""Half the minimum diameter allowed by the Rules of Golf (1.680 in = 42.67 mm)."""

BALL_AREA_M2 = 3.141592653589793 * BALL_RADIUS_M**2
"""Cross-sectional area A = pi R^2."""

BALL_INERTIA_KG_M2 = 0.4 * BALL_MASS_KG * BALL_RADIUS_M**2
"""Moment of inertia of a uniform sphere, I = 2/5 m R^2 (paper eq. 2)."""

GRAVITY_MPS2 = 9.80665
"""Standard gravity."""

TEE_HEIGHT_M = 0.01
"""Initial ball height r0_z (paper section 2.3.1): 1 cm above the ground plane."""

RPM_TO_RADPS = 2.0 * 3.141592653589793 / 60.0
MPH_TO_MPS = 0.44704
YARD_M = 0.9144
FOOT_M = 0.3048
