"""The linear programs of the jerk-limited timing (``toptraj.planners.timing.jerk.program``) solved over
a working set of their rows: a cutting-plane loop around HiGHS's dual simplex.

Each LP holds some 50 rows per grid interval on a 6-joint arm (second-order rows at the points
and the middles, jerk rows at both ends, the velocity bound at the quarters) for two columns,
and at its optimum only about two of them per point are active. The dual simplex solves the LP
restricted to a working set W of rows; the solution is then checked against every row (one
sparse product), the rows it violates join W, and the simplex continues from its basis, which
stays dual feasible when rows are added (row generation, as in Dantzig, Fulkerson & Johnson,
"Solution of a large-scale traveling-salesman problem", J. Oper. Res. Soc. Am. 2(4), 1954). A
round adds the most violated row of each grid point (``SELECTIVE_ROUNDS`` rounds), then every
row violated or near a bound; past ``MAX_ROUNDS``, or where HiGHS gives up on a relaxation, the
whole LP is solved from scratch. It ends when no row outside W is violated by more than the
solver's own feasibility tolerance: the solution of the relaxation is then feasible for the
whole LP, hence optimal for it (its objective that of the whole LP, up to that tolerance).

The rows of consecutive restrictions keep their order, so W and the basis carry over from one
LP to the next: the rows active at one restriction's optimum are those likely active at the
next.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse

from toptraj.planners.errors import BudgetExceeded, InfeasiblePath, TimingFailed
from toptraj.planners.execution.deadline import Deadline

#: HiGHS's primal feasibility tolerance, and the violation above which a row joins W. Near an
#: end at rest the jerk rows' right-hand sides are as small as x there (1e-8 of the typical
#: x): HiGHS's default of 1e-7 would let them be exceeded twofold.
FEASIBILITY = 1e-10
#: Rounds that add only the most violated row of each grid point (the rows of a point mostly
#: cut the same corner off, and most never bind); later rounds add every row violated or
#: within ``SEED_MARGIN`` of a bound.
SELECTIVE_ROUNDS = 10
#: Most rounds of adding violated rows to one LP before the whole LP is solved instead (a
#: guard against cycling on rounding noise).
MAX_ROUNDS = 40
#: HiGHS's value of ``simplex_dual_edge_weight_strategy`` for Devex pricing.
DEVEX = 1
#: Distance from a bound (the rows are scaled to a largest coefficient of one, the columns to
#: values of order one) within which a row is active enough at a seed to start in W.
SEED_MARGIN = 1e-2


class _Unsettled(Exception):
    """HiGHS ended a relaxation without a verdict."""


class WorkingSetLP:
    """Solves a sequence of LPs with the same rows (in order and number), each over the
    working set left by the previous one (module docstring).

    Attributes:
        rows: Indices of the rows in W, in the order HiGHS holds them.
        basis: HiGHS's basis at the last optimum (columns, then the rows of ``rows``).
    """

    def __init__(self, deadline: Deadline):
        self.deadline = deadline
        self.rows: np.ndarray | None = None
        self.basis = None
        self.total = 0
        self._part_of: np.ndarray | None = None
        self._part_pattern: tuple[np.ndarray, np.ndarray, np.ndarray] = (np.zeros(0), np.zeros(0), np.zeros(0))

    def solve(
        self, objective: np.ndarray, matrix: sparse.csr_matrix, lower: np.ndarray, upper: np.ndarray, low: np.ndarray,
        high: np.ndarray, seed: np.ndarray | None = None) -> np.ndarray:
        """The optimal column values of min objective.x, lower <= matrix x <= upper,
        low <= x <= high (``matrix`` (rows, columns), CSR). The first LP's working set holds
        the rows with equal bounds and, given a ``seed`` (column values near the optimum), the
        rows within ``SEED_MARGIN`` of a bound there. Raises ``InfeasiblePath``,
        ``TimingFailed`` or ``BudgetExceeded`` as the full LP would."""
        if self.rows is None or self.rows.size and self.rows.max() >= matrix.shape[0]:
            # Rows with equal bounds (the continuity of x) make every solution's skeleton.
            start = lower == upper
            if seed is not None:
                activity = matrix @ seed
                start |= (activity > upper - SEED_MARGIN) | (activity < lower + SEED_MARGIN)
            self.rows, self.basis = np.flatnonzero(start), None
        self.total = matrix.shape[0]
        try:
            return self._solve(objective, matrix, lower, upper, low, high)
        except _Unsettled:
            # HiGHS gave up on the relaxation from its warm start (numerical trouble): the
            # whole LP from scratch, its presolve on.
            self.rows, self.basis = np.arange(matrix.shape[0]), None
            return self._solve(objective, matrix, lower, upper, low, high, presolve=True)

    def _solve(self, objective, matrix, lower, upper, low, high, presolve: bool = False) -> np.ndarray:
        """The loop of the module docstring from the working set in ``rows``."""
        solver = self._model(objective, matrix, lower, upper, low, high, presolve)
        in_set = np.zeros(matrix.shape[0], dtype=bool)
        in_set[self.rows] = True
        for round_ in range(MAX_ROUNDS):
            if self._run(solver):
                values = np.asarray(solver.getSolution().col_value)
                activity = matrix @ values
                violated = np.flatnonzero(~in_set & ((activity > upper + FEASIBILITY) | (activity < lower - FEASIBILITY)))
                if round_ < SELECTIVE_ROUNDS:
                    violated = _worst_per_point(violated, np.maximum(activity - upper, lower - activity)[violated], matrix)
                elif violated.size:  # slow progress: the rows near a bound join too
                    violated = np.flatnonzero(~in_set & ((activity > upper - SEED_MARGIN) | (activity < lower + SEED_MARGIN)))
            else:  # a relaxation without a bound in some direction: every row joins
                violated = np.flatnonzero(~in_set)
            if violated.size == 0:
                break
            added = matrix[violated]
            solver.addRows(
                violated.size, lower[violated], upper[violated], added.nnz,
                added.indptr[:-1].astype(np.int32), added.indices.astype(np.int32), added.data,
            )
            in_set[violated] = True
            self.rows = np.concatenate([self.rows, violated])
        else:
            raise _Unsettled
        self.basis = solver.getBasis()
        return values

    def _model(self, objective, matrix, lower, upper, low, high, presolve: bool):
        """HiGHS holding the LP over the rows of W, started from the last basis."""
        import highspy

        self.deadline.check()
        solver = highspy.Highs()
        solver.setOptionValue("output_flag", False)
        solver.setOptionValue("primal_feasibility_tolerance", FEASIBILITY)
        # Devex pricing: the dual steepest-edge weights HiGHS computes by default, anew for every
        # warm start, cost more than they save on these LPs (a third of the LP time of the ur5
        # example; the same optima).
        solver.setOptionValue("simplex_dual_edge_weight_strategy", DEVEX)
        if not presolve:  # a warm start skips it anyway; a relaxation gains nothing from it
            solver.setOptionValue("presolve", "off")
        remaining = self.deadline.remaining()
        if remaining is not None:
            solver.setOptionValue("time_limit", max(remaining, 1e-3))
        rows = self.rows
        assert rows is not None
        start, index, taken = self._part(matrix, rows)
        lp = highspy.HighsLp()
        lp.num_col_, lp.num_row_ = matrix.shape[1], rows.size
        lp.col_cost_, lp.col_lower_, lp.col_upper_ = objective, low, high
        lp.row_lower_, lp.row_upper_ = lower[rows], upper[rows]
        lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
        lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = start, index, matrix.data[taken]
        solver.passModel(lp)
        if self.basis is not None:
            solver.setBasis(self.basis)
        return solver

    def _part(self, matrix: sparse.csr_matrix, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The rows ``rows`` of ``matrix`` by columns (CSC): its ``indptr`` and ``indices``, and
        the entries of ``matrix.data`` it takes, in order. Consecutive LPs share their pattern
        (only the jerk rows' values change) and mostly their working set: kept while
        ``rows`` is the same array."""
        if self._part_of is not rows:
            numbered = sparse.csr_matrix(
                (np.arange(matrix.nnz, dtype=float), matrix.indices, matrix.indptr), shape=matrix.shape,
            )
            part = numbered[rows].tocsc()
            self._part_of, self._part_pattern = rows, (part.indptr, part.indices, part.data.astype(np.int64))
        return self._part_pattern

    def _run(self, solver) -> bool:
        """One simplex run: ``True`` at an optimum, ``False`` where the relaxation is unbounded
        (rows outside W missing); HiGHS's other statuses as the library's errors."""
        import highspy

        solver.run()
        status = solver.getModelStatus()
        if status in (highspy.HighsModelStatus.kUnbounded, highspy.HighsModelStatus.kUnboundedOrInfeasible):
            if self.rows is not None and self.rows.size < self.total:
                return False
        if status == highspy.HighsModelStatus.kTimeLimit:
            self.deadline.check()
            raise BudgetExceeded(f"planning exceeded its time budget of {self.deadline.budget_s:.3g} s", budget_s=self.deadline.budget_s)
        if status == highspy.HighsModelStatus.kInfeasible:
            raise InfeasiblePath(
                "no jerk-limited motion follows the path within the limits (the linear program is infeasible)"
            )
        if status != highspy.HighsModelStatus.kOptimal and self.rows is not None and self.rows.size < self.total:
            raise _Unsettled
        if status != highspy.HighsModelStatus.kOptimal:
            raise TimingFailed(
                f"the jerk-limited timing's linear program ended without a solution (HiGHS: "
                f"{solver.modelStatusToString(status).lower()})",
                rule="jerk_program_unsolved", method="jerk_limited", solver_status=solver.modelStatusToString(status).lower(),
            )
        return True


def _worst_per_point(rows: np.ndarray, violation: np.ndarray, matrix: sparse.csr_matrix) -> np.ndarray:
    """Of the violated ``rows``, the most violated one per grid point (a row's point: its
    first column, modulo the points; the rows are scaled to a largest coefficient of one,
    so that their violations compare): a point's rows mostly cut the same corner off."""
    points = (matrix.shape[1] // 2)
    first = matrix.indices[matrix.indptr[rows]] % points
    order = np.lexsort((-violation, first))
    keep = np.ones(order.size, dtype=bool)
    keep[1:] = first[order][1:] != first[order][:-1]
    return np.sort(rows[order[keep]])
