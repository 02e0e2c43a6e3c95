"""Optimal-control references for the mdi-envs systems (Yunt & Glocker, HSCC 2007, problem 34).

``load_reference(name)`` reads a shipped reference with numpy only. Computing one needs CasADi
(``pip install 'mdi-envs[optimal]'``): ``optimal.solve.solve_problem`` or
``mdi-envs optimize NAME``. See ``optimal/README.md``.
"""

from optimal.references import Reference, available_references, load_reference

__all__ = ["Reference", "available_references", "load_reference"]
