"""The docs say what is: no development history in the documentation, docstrings or comments."""

from __future__ import annotations

import logging
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
HISTORY = re.compile(
    r"\bsession[- ]\d+|\bissue[- ]?\d+|\bscratch (?:run|probe|measurement|launcher)s?\b"
    r"|\bused to (?:be|take|wait|run|give|reach|cost)\b|\bnot kept\b|\bwork period"
    r"|\bshipped before\b|\bbefore this (?:change|module)",
    re.IGNORECASE)
"""Phrases that narrate how the code came to be rather than what it is."""
CHECKED = ["README.md", "docs", "mdi_envs", "optimal", "baselines", "benchmarks", "tests"]
"""What is kept free of history (files and folders, recursively: .md and .py)."""
SUB_READMES = ["optimal/README.md", "baselines/README.md", "benchmarks/README.md",
               "mdi_envs/stepping/README.md", "baselines/search/README.md"]
"""The folder maps beside the README."""


def test_readmes_are_short() -> None:
    """README.md at most 200 lines, each folder map at most 150, all together at most 800."""
    lengths = {name: len((ROOT / name).read_text(encoding="utf-8").splitlines())
               for name in ["README.md", *SUB_READMES]}
    assert lengths["README.md"] <= 200, lengths
    assert all(lengths[name] <= 150 for name in SUB_READMES), lengths
    assert sum(lengths.values()) <= 800, lengths


def _files() -> list[Path]:
    paths: list[Path] = []
    for name in CHECKED:
        path = ROOT / name
        paths += [path] if path.is_file() else sorted(
            p for suffix in ("*.md", "*.py") for p in path.rglob(suffix))
    return paths


def test_no_development_history() -> None:
    hits = [f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
            for path in _files()
            for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
            if HISTORY.search(line)]
    assert not hits, "development history:\n" + "\n".join(hits)


def test_docstrings_parse_as_google() -> None:
    """Every docstring of the documented packages parses cleanly (what the API pages render)."""
    griffe = pytest.importorskip("griffe")
    problems: list[str] = []

    class Collect(logging.Handler):
        def emit(self, record: logging.LogRecord) -> None:
            if record.levelno >= logging.WARNING:
                problems.append(record.getMessage())

    handler = Collect()
    logger = logging.getLogger("griffe")
    logger.addHandler(handler)
    try:
        loader = griffe.GriffeLoader(search_paths=[str(ROOT)])
        stack = [loader.load(name) for name in ("mdi_envs", "optimal", "baselines")]
        while stack:
            obj = stack.pop()
            if obj.docstring is not None:  # the options of mkdocs.yml
                obj.docstring.parse("google", warn_unknown_params=False,
                                    warn_missing_types=False)
            stack += [m for name, m in obj.members.items()
                      if not m.is_alias and not name.startswith("_")]
    finally:
        logger.removeHandler(handler)
    assert not problems, "\n".join(problems)
