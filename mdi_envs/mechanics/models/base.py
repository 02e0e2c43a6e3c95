"""The one definition of a mechanical model, read by the simulator, the optimizer and the tests.

A model is a class whose static methods state the equations of

    M(q) du = (h(q, u) + B(q) tau) dt + W_N dP_N + W_T dP_T + W_B dP_B

with scalar arithmetic and an ``ops`` namespace for the elementary functions (``sin``, ``cos``,
``sqrt``). The same source is evaluated three ways, so that no formula exists twice:

* compiled (numba): ``ops`` is the ``math`` module and the equations run inside the stepper's
  kernels (``mdi_envs.mechanics.compiled``);
* symbolic (CasADi): ``ops`` is the ``casadi`` module and ``q``, ``u`` are ``SX`` vectors
  (``mdi_envs.mechanics.symbolic``, used by ``optimal/``);
* plain Python with ``ops = math``, for tests and tooling.

Conventions: every equation returns (nested) tuples of floats -- rows of a matrix, entries of a
vector -- and uses float literals (``0.0``, not ``0``) so that numba types them uniformly.
``p`` is the model's parameter record (a NamedTuple of floats, from ``parameters.values()``).
Contact i contributes ``contact_dimension`` rows to ``contact_directions``: the normal row
``W_N,i^T`` followed by its tangent rows, so that ``gamma = row . u`` is a relative velocity.
"""

from __future__ import annotations

from typing import Any, ClassVar, NamedTuple


class ModelDefinition:
    """Base class of the models: structure as class constants, equations as static methods.

    Subclasses set the class constants and implement every static method. Shapes use
    ``n = NUM_DOFS``, ``m = NUM_INPUTS``, ``c = NUM_CONTACTS``, ``d = CONTACT_DIMENSION``,
    ``k = NUM_BRAKES``.
    """

    NAME: ClassVar[str]
    NUM_DOFS: ClassVar[int]
    NUM_INPUTS: ClassVar[int]
    NUM_CONTACTS: ClassVar[int] = 0
    CONTACT_DIMENSION: ClassVar[int] = 2  # 2: planar (normal, tangent); 3: spatial
    NUM_BRAKES: ClassVar[int] = 0
    HAS_CONSTANT_MASS: ClassVar[bool] = False
    HAS_LOAD_TRANSFER: ClassVar[bool] = False  # normal impulses from ``normal_loads``, not gaps
    # h depends on u (Coriolis, centrifugal, damping): at most quadratically, as in any
    # Lagrangian model. The stepper then treats it by the theta = 1/2 scheme (moreau_jean.py).
    HAS_VELOCITY_FORCES: ClassVar[bool] = True
    COORDINATE_NAMES: ClassVar[tuple[str, ...]]

    @staticmethod
    def mass_matrix(q: Any, p: NamedTuple, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """M(q): n rows of n entries [kg, kg m, kg m^2 by coordinate]."""
        raise NotImplementedError

    @staticmethod
    def forces(q: Any, u: Any, p: NamedTuple, ops: Any) -> tuple[Any, ...]:
        """h(q, u): n generalized forces (gyroscopic, Coriolis, gravity) [N or N m]."""
        raise NotImplementedError

    @staticmethod
    def input_matrix(q: Any, p: NamedTuple, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """B(q): n rows of m entries, mapping the inputs tau to generalized forces."""
        raise NotImplementedError

    @staticmethod
    def gaps(q: Any, p: NamedTuple, ops: Any) -> tuple[Any, ...]:
        """g(q): c normal distances [m]; contact i is closed when g_i <= 0."""
        return ()

    @staticmethod
    def contact_directions(q: Any, p: NamedTuple, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """C * d rows of n entries: per contact the normal row, then its tangent rows."""
        return ()

    @staticmethod
    def restitutions(p: NamedTuple) -> tuple[float, ...]:
        """C Newton restitution coefficients eps_i in [0, 1] (normal direction)."""
        return ()

    @staticmethod
    def friction_coefficients(p: NamedTuple) -> tuple[float, ...]:
        """C Coulomb friction coefficients mu_i >= 0."""
        return ()

    @staticmethod
    def normal_loads(p: NamedTuple) -> tuple[tuple[float, ...], tuple[tuple[float, ...], ...]]:
        """Normal forces N = N0 + K F [N] as a linear function of the friction forces F.

        Only for models with HAS_LOAD_TRANSFER (their contacts are always closed). Returns
        (N0 (c,), K as c rows of c*(d-1) entries).
        """
        raise NotImplementedError

    @staticmethod
    def slip_mode(sliding: Any) -> int:
        """The model's mode label from per-contact slide flags (c,); 0 for models without."""
        return 0

    @staticmethod
    def brake_directions(q: Any, p: NamedTuple, ops: Any) -> tuple[tuple[Any, ...], ...]:
        """K rows of n entries: the relative velocity each brake can block."""
        return ()


__all__ = ["ModelDefinition"]
