"""``git_commit``: HEAD, marked dirty when a tracked file changed; None outside a checkout."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from mdi_envs import provenance


def _git(root: Path, *arguments: str) -> str:
    return subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *arguments],
                          cwd=root, capture_output=True, text=True, check=True).stdout.strip()


def test_git_commit_is_head_dirty_only_with_changed_tracked_files(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    _git(tmp_path, "init", "-q")
    (tmp_path / "model.py").write_text("x = 1\n")
    _git(tmp_path, "add", "model.py")
    _git(tmp_path, "commit", "-q", "-m", "a model")
    head = _git(tmp_path, "rev-parse", "HEAD")
    monkeypatch.setattr(provenance, "ROOT", tmp_path)
    assert provenance.git_commit() == head
    (tmp_path / "run_seed0.json").write_text("{}\n")  # an output, not tracked
    assert provenance.git_commit() == head
    (tmp_path / "model.py").write_text("x = 2\n")
    assert provenance.git_commit() == head + "+dirty"


def test_git_commit_is_none_outside_a_checkout(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(provenance, "ROOT", tmp_path)
    monkeypatch.setenv("GIT_CEILING_DIRECTORIES", str(tmp_path.parent))
    assert provenance.git_commit() is None
