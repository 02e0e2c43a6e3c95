"""The registry of mixed-LCP methods; each method module registers itself here on import."""

from __future__ import annotations

from mdi_envs.solvers._registry import MethodRegistry

MLCP_METHODS = MethodRegistry("MLCP")

__all__ = ["MLCP_METHODS"]
