"""The speed dependence of the support friction, shared by the model and the testbed.

``mu(v) = mu_ref max(1 + gain log10(max(v, SPEED_FLOOR) / SPEED_REFERENCE), MIN_FRICTION_FACTOR)`` for the
sliding speed ``v``: the pushing model's ``friction_speed`` effect (:mod:`pushjax.physics.effects`) and the testbed's
``friction_speed_gain`` (:mod:`pushjax.sim.testbed`) use these constants. They live here, below both, with no imports,
so that :mod:`pushjax.sim` stays free of JAX.
"""

SPEED_REFERENCE = 0.02
"""Sliding speed in m/s at which the speed-dependent coefficient is the reference one (the MIT grid's 20 mm/s)."""
SPEED_FLOOR = 1e-3
"""Sliding speed in m/s below which the speed-dependent coefficient stops changing (static contact)."""
MIN_FRICTION_FACTOR = 0.1
"""Smallest factor of the speed-dependent coefficient."""
