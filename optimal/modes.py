"""Mode patterns: the discrete part of a solution, one boolean per brake or contact and interval.

A solution of problem (34) is a mode sequence plus the continuous trajectory within it. The
penalty/continuation (``optimal.continuation``) chooses the sequence implicitly; the global
search (``optimal.mode_search``) moves it explicitly. A ``ModePattern`` holds, per interval k of
the grid,

* ``engaged`` (k_B, N): brake j engaged over interval k (xi_B = W_B u_{k+1} = 0, P_B free), else
  released (P_B = 0);
* ``sliding`` (c, N): contact i slides over interval k (P_T on the friction cone against the
  slip), else sticks (slip = 0);

and ``Transcription(problem, modes=pattern)`` states exactly those laws, so that one NLP with
the pattern fixed is smooth (no complementarity left) and IPOPT optimizes the switching times
and t_f within it. The moves of the mode-neighbourhood search are ``ModePattern.neighbours``.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

BoolArray = np.ndarray
"""A numpy array of dtype bool."""


@dataclass(frozen=True, eq=False)
class ModePattern:
    """Which mode each brake and each contact is in, per interval.

    Attributes:
        engaged: (k_B, N) bool, brake engaged over the interval; None for models without
            brakes.
        sliding: (c, N) bool, contact slides over the interval; None for models without
            friction contacts.
    """

    engaged: BoolArray | None = None
    sliding: BoolArray | None = None

    def __post_init__(self) -> None:
        widths = {np.shape(rows)[1] for rows in self._parts() if rows is not None}
        for name, rows in zip(("engaged", "sliding"), self._parts(), strict=True):
            if rows is not None and (np.ndim(rows) != 2 or np.asarray(rows).dtype != bool):
                raise ValueError(f"{name} must be a 2-d bool array, got {np.asarray(rows)!r}")
        if len(widths) > 1:
            raise ValueError(f"engaged and sliding must have the same number of intervals, "
                             f"got {sorted(widths)}")

    def _parts(self) -> tuple[BoolArray | None, BoolArray | None]:
        return self.engaged, self.sliding

    @property
    def num_intervals(self) -> int:
        """N, the number of intervals the pattern covers."""
        for rows in self._parts():
            if rows is not None:
                return int(np.shape(rows)[1])
        return 0

    def key(self) -> bytes:
        """A hashable identity of the pattern (equal patterns, equal keys)."""
        return b"|".join(b"-" if rows is None else np.packbits(rows).tobytes()
                         + str(np.shape(rows)).encode() for rows in self._parts())

    def intervals(self, index: object) -> ModePattern:
        """The pattern of the intervals ``index`` selects (a slice or an index array)."""
        return ModePattern(*(None if rows is None else rows[:, index] for rows in self._parts()))

    def refined(self, factor: int) -> ModePattern:
        """The same pattern on a grid ``factor`` times finer (each interval repeated)."""
        if factor < 1:
            raise ValueError(f"factor must be a positive integer, got {factor}")
        return self.intervals(np.repeat(np.arange(self.num_intervals), factor))

    def neighbours(self, max_shift: int = 2) -> list[tuple[str, ModePattern]]:
        """The patterns one move away, each with a label, without duplicates or itself.

        Moves, per row (a brake or a contact): each switch between two phases shifted by
        +-1 ... +-``max_shift`` intervals (a shift that reaches the next switch merges the
        phases); each phase flipped to the other mode (merging its neighbours); each phase of
        3 or more intervals split by flipping its middle interval.
        """
        seen = {self.key()}
        result: list[tuple[str, ModePattern]] = []
        for part, row_index, label, row in self._rows():
            for move, new_row in _row_moves(row, max_shift):
                pattern = self._with_row(part, row_index, new_row)
                if pattern.key() not in seen:
                    seen.add(pattern.key())
                    result.append((f"{label}: {move}", pattern))
        return result

    def phases(self, time: np.ndarray) -> dict[str, list[tuple[float, float]]]:
        """The intervals [s] of the engaged brakes and sliding contacts.

        Args:
            time: (N+1,) grid times [s].

        Returns:
            {"brake j" or "contact i": [(start, end), ...]} of the True runs.
        """
        return {label: [(float(time[start]), float(time[stop]))
                        for start, stop, value in _runs(row) if value]
                for _, _, label, row in self._rows()}

    def _rows(self) -> Iterator[tuple[int, int, str, BoolArray]]:
        for part, (name, rows) in enumerate(zip(("brake", "contact"), self._parts(),
                                                strict=True)):
            if rows is not None:
                for index, row in enumerate(rows):
                    yield part, index, f"{name} {index}", row

    def _with_row(self, part: int, row_index: int, row: BoolArray) -> ModePattern:
        parts = [None if rows is None else rows.copy() for rows in self._parts()]
        target = parts[part]
        assert target is not None
        target[row_index] = row
        return ModePattern(*parts)


def _runs(row: BoolArray) -> list[tuple[int, int, bool]]:
    """(start, stop, value) of the maximal constant runs of ``row``, stop exclusive."""
    switches = np.flatnonzero(row[1:] != row[:-1]) + 1
    bounds = [0, *switches.tolist(), row.size]
    return [(start, stop, bool(row[start])) for start, stop in zip(bounds, bounds[1:],
                                                                       strict=False)]


def _row_moves(row: BoolArray, max_shift: int) -> Iterator[tuple[str, BoolArray]]:
    """The moves of one row: shifted switches, flipped phases, split phases."""
    runs = _runs(row)
    for (_, switch, left), _ in zip(runs, runs[1:], strict=False):
        for shift in (s for step in range(1, max_shift + 1) for s in (-step, step)):
            new = row.copy()
            if shift > 0:
                new[switch:switch + shift] = left
            else:
                new[max(switch + shift, 0):switch] = not left
            yield f"switch at {switch} shifted by {shift:+d}", new
    if len(runs) > 1:
        for start, stop, value in runs:
            new = row.copy()
            new[start:stop] = not value
            yield f"phase {start}-{stop} flipped", new
    for start, stop, value in runs:
        if stop - start >= 3:
            new = row.copy()
            new[(start + stop) // 2] = not value
            yield f"phase {start}-{stop} split", new


__all__ = ["ModePattern"]
