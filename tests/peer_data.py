"""Location of the peer (Siconos) problems for tests; parameters skip cleanly when absent."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

PEER_DATA = Path(
    os.environ.get(
        "MDI_ENVS_PEER_DATA",
        Path(__file__).resolve().parents[1].parent / "shared" / "peer-data" / "siconos",
    )
)


def peer_files(kind: str) -> list[Path]:
    """Sorted peer problem files of one kind (``"lcp"``, ``"fc2d"``, ``"fc3d"``); [] if absent."""
    folder = PEER_DATA / kind
    return sorted(folder.glob("*.dat")) if folder.is_dir() else []


def peer_params(kind: str, names: list[str] | None = None) -> list[object]:
    """``pytest.param`` per peer file (optionally only ``names``, given as file stems).

    When ../shared is absent this is a single skipped parameter, so the test reports a clean
    skip instead of silently vanishing.
    """
    files = peer_files(kind)
    if names is not None:
        files = [f for f in files if f.stem in names]
    if not files:
        return [pytest.param(None, marks=pytest.mark.skip(reason=f"peer data {PEER_DATA} absent"))]
    return [pytest.param(f, id=f.stem) for f in files]
