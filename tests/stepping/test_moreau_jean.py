"""``MoreauJeanStepper``: input validation, diagnostics and ``step_batch`` against ``step``.

The physics of each model is tested in ``test_moreau_jean_ball.py``, ``..._block.py`` and
``..._manipulator.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from mdi_envs.mechanics.models import (
    BlockableManipulator,
    BlockableManipulatorParameters,
    BouncingBall,
    BouncingBallParameters,
    SlidingBlock,
    SlidingBlockParameters,
)
from mdi_envs.solvers.status import SolverStatus
from mdi_envs.stepping import MoreauJeanStepper

Stepper = Callable[..., MoreauJeanStepper]


# ----------------------------------------------------------------------------- step_batch
def random_batch(model: type, rng: np.random.Generator, num_copies: int
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """States, inputs and brake bounds that exercise every branch of the model's step."""
    n, m, k = model.NUM_DOFS, model.NUM_INPUTS, model.NUM_BRAKES
    if model is BlockableManipulator:
        q = rng.uniform(-np.pi, np.pi, (num_copies, n))
        u = rng.normal(0.0, 2.0, (num_copies, n))
    else:
        # Half the copies on or just inside the contact, half in the air.
        q = np.column_stack([rng.normal(0.0, 1.0, num_copies),
                             rng.choice([-1e-3, 0.0, 0.05, 0.3], num_copies)])  # fmt: skip
        if model is BouncingBall:
            q[:, 1] += 0.05
        u = rng.normal(0.0, 1.0, (num_copies, n))
    tau = rng.normal(0.0, 3.0, (num_copies, m))
    brake = rng.choice([0.0, np.inf, 0.4, 30.0], (num_copies, k))
    return q, u, tau, brake


@pytest.mark.parametrize("num_substeps", [1, 7])
@pytest.mark.parametrize("model", [BouncingBall, SlidingBlock, BlockableManipulator])
def test_step_batch_equals_step_copy_by_copy(
    make_stepper: Stepper, model: type, num_substeps: int
) -> None:
    """Same states (bitwise), impulses and info as ``step`` in a loop; worst status reported."""
    rng = np.random.default_rng(11)
    parameters = {"friction_coefficient": 0.3} if model is BouncingBall else {}
    stepper = make_stepper(model, 2e-3, **parameters)
    q0, u0, tau, brake = random_batch(model, rng, 24)
    q, u = q0.copy(), u0.copy()
    impulses, info = stepper.step_batch(q, u, tau, brake, num_substeps=num_substeps)
    branches = set()
    for e in range(len(q0)):
        qe, ue = q0[e], u0[e]
        worst = 0
        for _ in range(num_substeps):
            result = stepper.step(qe, ue, tau[e], brake[e])
            qe, ue = result.q, result.u
            worst = max(worst, int(result.status))
            branches.add((result.num_active_contacts, result.lcp_size, result.num_equalities))
        np.testing.assert_array_equal(q[e], qe)
        np.testing.assert_array_equal(u[e], ue)
        np.testing.assert_array_equal(impulses[e], result.impulses)
        assert info[e, 0] == worst
        assert tuple(info[e, 1:5]) == (result.num_iter, result.num_active_contacts,
                                       result.lcp_size, result.num_equalities)  # fmt: skip
    # The batch really mixes branches (open/closed contacts, released/ideal/Tresca brakes).
    assert len(branches) >= 2


def test_step_batch_calls_chain(make_stepper: Stepper) -> None:
    """Two calls of 5 substeps = one call of 10 = ten steps."""
    stepper = make_stepper(BlockableManipulator, 1e-3)
    rng = np.random.default_rng(12)
    q0, u0, tau, brake = random_batch(BlockableManipulator, rng, 8)
    q_a, u_a = q0.copy(), u0.copy()
    stepper.step_batch(q_a, u_a, tau, brake, num_substeps=5)
    stepper.step_batch(q_a, u_a, tau, brake, num_substeps=5)
    q_b, u_b = q0.copy(), u0.copy()
    stepper.step_batch(q_b, u_b, tau, brake, num_substeps=10)
    np.testing.assert_array_equal(q_a, q_b)
    np.testing.assert_array_equal(u_a, u_b)


# ----------------------------------------------------------------------------- diagnostics
def test_step_diagnostics_describe_the_solved_problem(make_stepper: Stepper) -> None:
    ball = make_stepper(BouncingBall, 1e-3)
    air = ball.step([0.0, 1.0], [0.0, 0.0], [0.0])
    assert (air.num_active_contacts, air.lcp_size, air.num_equalities) == (0, 0, 0)
    assert air.status is SolverStatus.CONVERGED and np.all(air.impulses == 0.0)
    ground = ball.step([0.0, 0.05], [0.0, -1.0], [0.0])
    assert (ground.num_active_contacts, ground.lcp_size) == (1, 1)  # frictionless: P_N only
    assert ground.impulses[0] > 0.0 and ground.impulses[1] == 0.0
    block = make_stepper(SlidingBlock, 1e-3).step([0.0, 0.0], [0.0, 0.0], [0.0])
    assert (block.num_active_contacts, block.lcp_size) == (1, 3)  # P_N, P_R, xi_L
    arm = make_stepper(BlockableManipulator, 1e-3)
    for bound, sizes in ((0.0, (0, 0)), (np.inf, (0, 1)), (3.0, (2, 0))):
        result = arm.step([0.0, 1.0], [1.0, -1.0], [0.0], [bound])
        assert (result.lcp_size, result.num_equalities) == sizes
        assert result.status is SolverStatus.CONVERGED


def test_step_does_not_modify_its_inputs(make_stepper: Stepper) -> None:
    stepper = make_stepper(BlockableManipulator, 1e-3)
    q, u, tau, brake = np.array([0.1, 0.2]), np.array([1.0, -1.0]), np.array([0.5]), [np.inf]
    stepper.step(q, u, tau, brake)
    assert list(q) == [0.1, 0.2] and list(u) == [1.0, -1.0] and list(tau) == [0.5]


def test_motor_torque_enters_through_b(make_stepper: Stepper) -> None:
    """From rest, brake released: M(q_M)(u+ - u) = B tau dt, B = (1, 0)."""
    dt = 1e-3
    stepper = make_stepper(BlockableManipulator, dt)
    q = np.array([0.4, -0.3])
    result = stepper.step(q, [0.0, 0.0], [2.5], [0.0])
    values = stepper.parameters.values()
    m = np.array(BlockableManipulator.mass_matrix(q, values, math))
    np.testing.assert_allclose(m @ result.u, [2.5 * dt, 0.0], rtol=0, atol=1e-15)


# ----------------------------------------------------------------------------- validation
@pytest.mark.parametrize(
    ("q", "u", "tau", "match"),
    [
        ([0.0, np.nan], [0.0, 0.0], [0.0], "q contains NaN"),
        ([np.inf, 1.0], [0.0, 0.0], [0.0], "q contains NaN or inf"),
        ([0.0, 1.0], [np.nan, 0.0], [0.0], "u contains NaN"),
        ([0.0, 1.0], [0.0, -np.inf], [0.0], "u contains NaN or inf"),
        ([0.0, 1.0], [0.0, 0.0], [np.nan], "tau contains NaN"),
        ([0.0, 1.0, 2.0], [0.0, 0.0], [0.0], r"q must have shape \(2,\)"),
        ([0.0, 1.0], [0.0], [0.0], r"u must have shape \(2,\)"),
        ([0.0, 1.0], [0.0, 0.0], [0.0, 1.0], r"tau must have shape \(1,\)"),
        ([[0.0, 1.0]], [0.0, 0.0], [0.0], r"q must have shape \(2,\), got \(1, 2\)"),
    ],
)
def test_step_rejects_bad_states(make_stepper: Stepper, q: list, u: list, tau: list,
                                 match: str) -> None:  # fmt: skip
    stepper = make_stepper(BouncingBall, 1e-3)
    with pytest.raises(ValueError, match=match):
        stepper.step(q, u, tau)


@pytest.mark.parametrize(
    ("bound", "match"),
    [
        ([-1.0], "brake_bound must be >= 0"),
        ([np.nan], "brake_bound must be >= 0"),
        ([-np.inf], "brake_bound must be >= 0"),
        ([1.0, 2.0], r"brake_bound must have shape \(1,\)"),
    ],
)
def test_step_rejects_bad_brake_bounds(make_stepper: Stepper, bound: list, match: str) -> None:
    stepper = make_stepper(BlockableManipulator, 1e-3)
    with pytest.raises(ValueError, match=match):
        stepper.step([0.0, 0.0], [0.0, 0.0], [0.0], bound)


def test_model_without_brakes_rejects_brake_bounds(make_stepper: Stepper) -> None:
    stepper = make_stepper(BouncingBall, 1e-3)
    stepper.step([0.0, 1.0], [0.0, 0.0], [0.0], [])  # the empty command is fine
    with pytest.raises(ValueError, match=r"brake_bound must have shape \(0,\)"):
        stepper.step([0.0, 1.0], [0.0, 0.0], [0.0], [0.0])


@pytest.mark.parametrize("time_step", [0.0, -1e-3, math.nan, math.inf, "0.001", None])
def test_rejects_bad_time_steps(time_step: object) -> None:
    with pytest.raises(ValueError, match="time_step must be a finite number > 0"):
        MoreauJeanStepper(BouncingBall, time_step=time_step)  # type: ignore[arg-type]


@pytest.mark.parametrize("time_step", [np.float32(1e-3), np.int64(1), np.float64(1e-3), 1])
def test_accepts_numpy_time_steps(make_stepper: Stepper, time_step: object) -> None:
    """Any finite positive real is a time step, numpy scalars included.

    FAILS (reported) for np.float32(1e-3) and np.int64(1): ``MoreauJeanStepper.__post_init__``
    checks ``isinstance(time_step, (int, float))``, which numpy's float32 and int64 are not,
    and raises "time_step must be a finite number > 0, got np.float32(0.001)".
    """
    make_stepper(BouncingBall, 1e-3)
    stepper = MoreauJeanStepper(BouncingBall, time_step=time_step)  # type: ignore[arg-type]
    result = stepper.step([0.0, 10.0], [0.0, 0.0], [0.0])
    assert result.u[1] == pytest.approx(-9.81 * float(time_step), rel=1e-6)


def test_rejects_parameters_of_another_model() -> None:
    """Parameters must belong to the model; the error is raised at construction.

    FAILS (reported): ``MoreauJeanStepper(BouncingBall, SlidingBlockParameters())`` is
    accepted; the first ``step`` then fails inside numba with
    ``numba.core.errors.TypingError: ... Unknown attribute 'radius'`` instead of a ValueError.
    """
    with pytest.raises(ValueError, match="parameters"):
        MoreauJeanStepper(BouncingBall, SlidingBlockParameters(), time_step=1e-3)


def test_step_batch_rejects_bad_arrays(make_stepper: Stepper) -> None:
    stepper = make_stepper(BlockableManipulator, 1e-3)
    good = np.zeros((3, 2))

    def call(q: object = None, u: object = None, tau: object = None, brake: object = None,
             num_substeps: object = 1) -> None:  # fmt: skip
        stepper.step_batch(
            good.copy() if q is None else q,
            good.copy() if u is None else u,
            np.zeros((3, 1)) if tau is None else tau,
            np.zeros((3, 1)) if brake is None else brake,
            num_substeps=num_substeps,
        )

    with pytest.raises(ValueError, match=r"q must be a C-contiguous float64 array of shape"):
        call(q=np.zeros((3, 2), dtype=np.float32))
    with pytest.raises(ValueError, match=r"q must be a C-contiguous"):
        call(q=np.zeros((2, 3)).T)
    with pytest.raises(ValueError, match=r"u must be a C-contiguous"):
        call(u=np.zeros(2))
    with pytest.raises(ValueError, match="u has 2 rows, q has 3"):
        call(u=np.zeros((2, 2)))
    with pytest.raises(ValueError, match=r"tau must be finite with shape \(3, 1\)"):
        call(tau=np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"tau must be finite"):
        call(tau=np.full((3, 1), np.nan))
    with pytest.raises(ValueError, match="brake_bound must be >= 0"):
        call(brake=np.full((3, 1), -1.0))
    with pytest.raises(ValueError, match=r"brake_bound must have shape \(3, 1\)"):
        call(brake=np.zeros((3, 2)))
    for bad in (0, -1, 1.5):
        with pytest.raises(ValueError, match="num_substeps must be a positive integer"):
            call(num_substeps=bad)


@pytest.mark.parametrize(("which", "value"), [("q", np.nan), ("u", np.inf)])
def test_step_batch_rejects_non_finite_states(
    make_stepper: Stepper, which: str, value: float
) -> None:
    """Documented: "Raises ValueError: ... NaN/inf inputs".

    FAILS (reported): ``step_batch`` checks q and u for dtype, shape and contiguity only. With
    Q = [[0, nan]], U = [[0, 0]] (BouncingBall) it returns normally and leaves Q = [[0, nan]],
    U = [[0, -0.00981]]: the NaN propagates silently (status CONVERGED).
    """
    stepper = make_stepper(BouncingBall, 1e-3)
    q, u = np.array([[0.0, 1.0], [0.0, 2.0]]), np.zeros((2, 2))
    (q if which == "q" else u)[1, 1] = value
    with pytest.raises(ValueError, match=f"{which} .*(NaN|inf|finite)"):
        stepper.step_batch(q, u, np.zeros((2, 1)))


# ----------------------------------------------------------------------------- parameters
@pytest.mark.parametrize(
    ("factory", "field", "value", "match"),
    [
        (BouncingBallParameters, "mass", -1.0, "'mass' must be > 0"),
        (BouncingBallParameters, "mass", 0.0, "'mass' must be > 0"),
        (BouncingBallParameters, "radius", math.nan, "'radius' must be a finite number"),
        (BouncingBallParameters, "gravity", -9.81, "'gravity' must be >= 0"),
        (BouncingBallParameters, "restitution", 1.01, r"'restitution' must lie in \[0, 1\]"),
        (BouncingBallParameters, "restitution", -0.1, r"'restitution' must lie in \[0, 1\]"),
        (BouncingBallParameters, "friction_coefficient", -0.1, "'friction_coefficient'"),
        (SlidingBlockParameters, "slope_angle", math.pi / 2, "'slope_angle' must lie in"),
        (SlidingBlockParameters, "slope_angle", 2.0, "'slope_angle' must lie in"),
        (SlidingBlockParameters, "slope_angle", -0.1, "'slope_angle' must lie in"),
        (SlidingBlockParameters, "friction_coefficient", -1e-9, "'friction_coefficient'"),
        (SlidingBlockParameters, "mass", math.inf, "'mass' must be a finite number"),
        (SlidingBlockParameters, "restitution", 2.0, "'restitution' must lie in"),
        (BlockableManipulatorParameters, "link1_mass", -1.0, "'link1_mass' must be > 0"),
        (BlockableManipulatorParameters, "link2_length", 0.0, "'link2_length' must be > 0"),
        (BlockableManipulatorParameters, "link1_length", "1", "'link1_length' must be a finite"),
        (BlockableManipulatorParameters, "link2_mass", True, "'link2_mass' must be a finite"),
    ],
)
def test_invalid_parameters_name_the_field(factory: type, field: str, value: object,
                                           match: str) -> None:  # fmt: skip
    with pytest.raises(ValueError, match=match):
        factory(**{field: value})


def test_valid_edge_parameters_are_accepted() -> None:
    BouncingBallParameters(restitution=0.0, friction_coefficient=0.0, gravity=0.0)
    BouncingBallParameters(restitution=1.0)
    SlidingBlockParameters(slope_angle=0.0, friction_coefficient=0.0)
    SlidingBlockParameters(slope_angle=math.pi / 2 - 1e-6)
