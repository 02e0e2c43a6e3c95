"""mdi-envs: nonsmooth rigid-body mechanics (Moreau-Jean MDIs) for control and RL.

Layers: ``solvers`` (complementarity problems), then the mechanics models, the time-stepper and
the Gymnasium environments as they land.
"""

__version__ = "0.1.0"

__all__ = ["__version__"]
