"""The registry of FC2D methods; each method module registers itself here on import."""

from __future__ import annotations

from mdi_envs.solvers._registry import MethodRegistry

FC2D_METHODS = MethodRegistry("FC2D")

__all__ = ["FC2D_METHODS"]
