"""mdi-envs: nonsmooth rigid-body mechanics (Moreau-Jean MDIs) for control and RL.

Layers: ``solvers`` (complementarity problems), ``mechanics`` (the models), ``stepping`` (the
Moreau-Jean stepper) and ``envs`` (Gymnasium environments). Importing the package registers the
``mdi_envs/...`` environment ids, so ``gym.make("mdi_envs/BlockableManipulator-v0")`` works.
"""

from mdi_envs import _kernel_cache
from mdi_envs._version import __version__

_kernel_cache.install_locator()  # before any cached kernel is defined: see _kernel_cache

from mdi_envs.registration import ENV_IDS, register_envs  # noqa: E402

register_envs()

__all__ = ["ENV_IDS", "__version__"]
