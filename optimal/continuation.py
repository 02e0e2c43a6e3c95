"""The combined penalty/continuation method (SUMT): solve the transcription stage by stage.

Stage s minimizes  cost / cost_unit + rho_s * sum(a b / scale) / N  subject to the dynamics,
the bounds and the relaxed complementarity a b / scale <= r_s, with IPOPT (exact first and
second derivatives from CasADi). rho rises and r falls along ``Schedule``; each stage starts
from the previous stage's primal solution. The first stage starts from the problem's naive
guess (``Transcription.set_naive_guess``). No mode sequence and no integer variable enters:
brake schedule and stick-slip modes are whatever the last stage converges to.

IPOPT meets the relaxed products only to its constraint tolerance (~1e-9), so an optional last
stage, the polish, takes the active sets the continuation found -- per pair, the smaller of
a and b (scaled) -- fixes that one to zero, and re-solves (for load-transfer models in a rebuilt
NLP that states each contact's mode without repeated rows, ``Transcription.polished``):
complementarity then holds to the solver's accuracy on linear equalities, and the remaining
NLP optimizes the switching times and t_f within the mode sequence the penalty stages chose
(it chooses no new one).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from optimal.transcription import Transcription

POLISH_RELAXATION = 1.0
"""The polish fixes one side of every pair to zero, so the products vanish and neither the
penalty (rho = 0 there) nor the relaxation is needed; r = 1 keeps that constraint inactive,
where a tiny r would leave IPOPT an interior of width r."""


BOUND_RELAXATION = 1e-8
"""IPOPT's ``bound_relax_factor`` in the penalty stages (its default)."""

POLISH_BOUND_RELAXATION = 1e-14
"""... and in the polish: with the default, an impulse fixed to zero may end at ~1e-8, which
the manipulator's sensitive dynamics amplify to centimetres over the maneuver."""


@dataclass(frozen=True)
class Schedule:
    """Penalty weights (rising) and relaxations (falling), one pair per stage.

    Attributes:
        penalties: rho_s, dimensionless, nondecreasing.
        relaxations: r_s, bound on each scaled product, nonincreasing.
        max_iterations: IPOPT iteration limit per stage.
        tolerance: IPOPT's ``tol`` per stage.
        polish: add the active-set polish stage (see the module docstring).
        mu_strategy: IPOPT's barrier-parameter update, "adaptive" or "monotone" (the robot's
            first stage, far from complementarity, runs 5-20x faster with "monotone").
    """

    penalties: tuple[float, ...] = (1e-2, 1e-1, 1.0, 1e1, 1e2, 1e3)
    relaxations: tuple[float, ...] = (1e-1, 1e-2, 1e-3, 1e-5, 1e-8, 1e-10)
    max_iterations: int = 3000
    tolerance: float = 1e-10
    polish: bool = True
    mu_strategy: str = "adaptive"

    def __post_init__(self) -> None:
        if len(self.penalties) != len(self.relaxations) or not self.penalties:
            raise ValueError("penalties and relaxations must be nonempty and of equal length")


SCHEDULES = {"diff_drive_time": Schedule(mu_strategy="monotone"),
             "diff_drive_effort": Schedule(mu_strategy="monotone")}
"""Per-problem continuation schedules (others: ``Schedule()``). The robot's first stage, from
the naive guess far from complementarity, takes 5-20x fewer IPOPT iterations with the monotone
barrier update."""


@dataclass(frozen=True)
class StageRecord:
    """One stage of the continuation.

    Attributes:
        stage: "penalty" or "polish".
        penalty: rho. relaxation: r. status: IPOPT's return status. iterations: IPOPT's.
        solve_time: wall time of the stage [s]. cost: the problem's cost at the stage's end
            (t_f [s] or effort [N^2 m^2 s]). final_time: t_f [s].
        residual: natural complementarity residual max min(a, b), scaled.
        product_residual: max a b, scaled.
    """

    stage: str
    penalty: float
    relaxation: float
    status: str
    iterations: int
    solve_time: float
    cost: float
    final_time: float
    residual: float
    product_residual: float


@dataclass
class ContinuationResult:
    """The last stage's solution and the history.

    Attributes:
        values: evaluates an expression of ``transcription`` at the last stage's point.
        history: one record per stage. success: the last stage solved (IPOPT converged or
            acceptable) with a residual below ``residual_tolerance``.
        transcription: the NLP of the last stage: the one solved, or for load-transfer
            models its polish NLP (``Transcription.polished``), which has the same variables.
    """

    values: Callable[[Any], Any]
    history: list[StageRecord] = field(default_factory=list)
    success: bool = False
    transcription: Transcription | None = None


def solve_continuation(
    transcription: Transcription,
    schedule: Schedule | None = None,
    progress: Callable[[str], None] | None = None,
    residual_tolerance: float = 1e-6,
    initial: np.ndarray | None = None,
) -> ContinuationResult:
    """Run the continuation from the naive guess (or from ``initial``).

    Args:
        transcription: the NLP. schedule: stages (default ``Schedule()``).
        progress: called with one line per stage (e.g. ``print``); None is silent.
        residual_tolerance: the last stage's natural residual must be below this for success.
        initial: (nx,) a point of the NLP's variables to start from (e.g. a fixed-pattern
            solution, ``optimal.mode_search``); None starts from the naive guess.
    """
    schedule = schedule or Schedule()
    opti = transcription.opti
    set_solver(transcription, schedule, BOUND_RELAXATION)
    if initial is None:
        transcription.set_naive_guess()
    else:
        opti.set_initial(opti.x, initial)
    history: list[StageRecord] = []
    values: Callable[[Any], Any] = opti.debug.value
    status = ""
    stages = [("penalty", rho, r) for rho, r in
              zip(schedule.penalties, schedule.relaxations, strict=True)]
    if schedule.polish:
        stages.append(("polish", 0.0, POLISH_RELAXATION))
    for kind, penalty, relaxation in stages:
        if kind == "polish":
            if transcription.problem.model.HAS_LOAD_TRANSFER:
                point = values(opti.x)
                transcription = transcription.polished(values)
                opti = transcription.opti
                opti.set_initial(opti.x, point)
            else:
                _fix_active_sets(transcription, values)
            set_solver(transcription, schedule, POLISH_BOUND_RELAXATION)
        opti.set_value(transcription.rho, penalty)
        opti.set_value(transcription.relaxation, relaxation)
        start = time.perf_counter()
        try:
            solution = opti.solve()
            values = solution.value
        except RuntimeError:  # IPOPT did not converge: keep its last iterate
            values = opti.debug.value
        elapsed = time.perf_counter() - start
        stats = opti.stats()
        status = str(stats.get("return_status", "unknown"))
        natural, product = transcription.residuals(values)
        final_time = transcription.final_time
        record = StageRecord(
            stage=kind, penalty=penalty, relaxation=relaxation, status=status,
            iterations=int(stats.get("iter_count", -1)), solve_time=elapsed,
            cost=float(values(transcription.cost)),
            final_time=final_time if isinstance(final_time, float) else float(values(final_time)),
            residual=natural, product_residual=product,
        )
        history.append(record)
        if progress is not None:
            progress(
                f"  stage {len(history)}/{len(stages)} {kind}: rho={penalty:.0e} "
                f"r={relaxation:.0e} {status} it={record.iterations} "
                f"cost={record.cost:.6g} t_f={record.final_time:.4f} s "
                f"residual={natural:.2e} ({elapsed:.1f} s)"
            )
        opti.set_initial(opti.x, values(opti.x))
    ok = status in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
    success = ok and bool(history) and history[-1].residual <= residual_tolerance
    return ContinuationResult(values=values, history=history, success=success,
                              transcription=transcription)


def set_solver(transcription: Transcription, schedule: Schedule,
               bound_relaxation: float) -> None:
    """IPOPT with CasADi's exact Hessian, quiet, with the schedule's limits.

    Setting a solver makes CasADi rebuild (expand and bake) the NLP at the next solve, about
    as long as a warm-started solve: when the transcription's solver already has these
    settings, nothing is done (``Transcription.solver_settings``), so a reused NLP is solved
    again at once.
    """
    settings = (schedule, bound_relaxation)
    if transcription.solver_settings == settings:
        return
    transcription.solver_settings = settings
    transcription.opti.solver(
        "ipopt", {"expand": True, "print_time": False},
        {"print_level": 0, "max_iter": schedule.max_iterations, "tol": schedule.tolerance,
         "acceptable_tol": 1e-7, "mu_strategy": schedule.mu_strategy,
         "bound_relax_factor": bound_relaxation, "sb": "yes"})


def _fix_active_sets(transcription: Transcription, values: Callable[[Any], Any]) -> None:
    """Constrain, per complementarity pair, the smaller of a and b (scaled) to zero.

    One variable can sit in two pairs (a normal impulse, say), so the same equality can come
    twice; a repeated equality would make the NLP rank-deficient for IPOPT. The pair entries are
    linear in the variables, so the equalities kept are a maximal independent subset of rows
    of their (constant) Jacobian, chosen by a column-pivoted QR factorization.
    """
    import casadi
    from scipy.linalg import qr

    opti = transcription.opti
    zeros = []
    for pair in transcription.pairs:
        a, b = casadi.vec(pair.a), casadi.vec(pair.b)
        a_values = np.asarray(values(a), dtype=float).ravel()
        b_values = np.asarray(values(b), dtype=float).ravel()
        zeros += [a[int(i)] if a_values[i] <= b_values[i] else b[int(i)]
                  for i in range(a_values.size)]
    if not zeros:
        return
    stacked = casadi.vertcat(*zeros)
    jacobian = values(casadi.jacobian(stacked, opti.x))
    jacobian = jacobian.toarray() if hasattr(jacobian, "toarray") else np.asarray(jacobian)
    _, diagonal, pivots = qr(jacobian.T, mode="economic", pivoting=True)
    scale = max(abs(float(diagonal[0, 0])), 1.0)
    rank = int(np.sum(np.abs(np.diag(diagonal)) > 1e-10 * scale))
    opti.subject_to(stacked[sorted(int(i) for i in pivots[:rank])] == 0)


__all__ = [
    "BOUND_RELAXATION", "POLISH_BOUND_RELAXATION", "POLISH_RELAXATION", "ContinuationResult",
    "SCHEDULES", "Schedule", "StageRecord", "set_solver", "solve_continuation",
]
