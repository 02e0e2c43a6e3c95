"""The registry of LCP methods; each method module registers itself here on import."""

from __future__ import annotations

from mdi_envs.solvers._registry import MethodRegistry

LCP_METHODS = MethodRegistry("LCP")

__all__ = ["LCP_METHODS"]
