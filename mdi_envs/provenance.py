"""Where a result comes from: the commit of the repository that produced it."""

from __future__ import annotations

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
"""The folder holding the package: the repository's root in a source checkout."""


def git_commit() -> str | None:
    """The repository's HEAD commit, "+dirty" appended with uncommitted changes.

    Changes are those of tracked files, as ``git describe --dirty`` counts them: files git does
    not track (a run's outputs written into the checkout) leave the commit clean. None outside a
    git checkout (an installed wheel) or without git.
    """
    try:
        commit, dirty = (
            subprocess.run(["git", *command], cwd=ROOT, capture_output=True, text=True,
                           check=True, timeout=10).stdout.strip()
            for command in (["rev-parse", "HEAD"],
                            ["status", "--porcelain", "--untracked-files=no"])
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return commit + ("+dirty" if dirty else "")


__all__ = ["git_commit"]
