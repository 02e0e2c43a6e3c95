"""The registry of FC3D methods; each method module registers itself here on import."""

from __future__ import annotations

from mdi_envs.solvers._registry import MethodRegistry

FC3D_METHODS = MethodRegistry("FC3D")

__all__ = ["FC3D_METHODS"]
