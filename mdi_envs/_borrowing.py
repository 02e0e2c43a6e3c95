"""``borrowing_njit``: numba compilation without reference counting, for the hot loops.

numba counts references to every array view it creates (an atomic increment when the view is
made, an atomic decrement when it dies), and prunes those pairs only within simple control
flow. A loop over copies that takes row views (``Q[e]``, ``info[i]``, ``row[10:]``) and
branches pays two atomic operations per view per copy: a third of the manipulator vector
env's time went to ``NRT_incref``/``NRT_decref`` (perf, 4096 copies).

A function compiled with numba's ``_nrt=False`` option (a private option of ``numba.njit``:
this module is its one use, so a numba change is fixed here) creates no such counts: its views
borrow the arrays its caller passed in. That is safe under three rules, which every function
decorated here follows:

* it allocates nothing (numba refuses to compile an allocation without the runtime, so this
  one is checked);
* no array it creates outlives the call (it returns scalars or None);
* the functions it calls that are not inlined return no arrays (such a new reference would
  never be released: the caller's buffer would leak).

numba compiles a callee first reached from a caller with the caller's ``_nrt`` unless the
callee sets it: every non-inlined function called from one decorated here passes
``REFERENCE_COUNTED`` to ``njit`` (else, compiled first from here, an allocation inside it
fails to compile, and its views go uncounted).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from numba import njit

REFERENCE_COUNTED: dict[str, bool] = {"_nrt": True}
"""``njit`` options of a function called (not inlined) from a ``borrowing_njit`` one: keep
numba's reference counting there rather than inherit its absence."""


def borrowing_njit(function: Callable[..., Any]) -> Any:
    """``numba.njit(function)`` without reference counting (see the module docstring)."""
    return njit(_nrt=False)(function)


__all__ = ["REFERENCE_COUNTED", "borrowing_njit"]
