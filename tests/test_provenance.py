"""``git_commit``: the checkout's HEAD, marked dirty when it has changes; None outside git."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from mdi_envs import provenance


def test_git_commit_is_the_checkouts_head() -> None:
    head, changes = (subprocess.run(["git", *command], cwd=provenance.ROOT, capture_output=True,
                                    text=True, check=False)
                     for command in (["rev-parse", "HEAD"], ["status", "--porcelain"]))
    if head.returncode:  # the sources are not a git checkout (an unpacked archive)
        assert provenance.git_commit() is None
    else:
        expected = head.stdout.strip() + ("+dirty" if changes.stdout.strip() else "")
        assert provenance.git_commit() == expected


def test_git_commit_is_none_outside_a_checkout(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(provenance, "ROOT", tmp_path)
    monkeypatch.setenv("GIT_CEILING_DIRECTORIES", str(tmp_path.parent))
    assert provenance.git_commit() is None
