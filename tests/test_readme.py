"""The README's example runs, and its results table is the one generated from committed JSON."""

from __future__ import annotations

import re
import sys
from pathlib import Path
from types import ModuleType

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"


def _section(title: str) -> str:
    """The README text under ``## title`` up to the next ``## ``."""
    text = README.read_text()
    return text.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]


def _headline() -> ModuleType:
    """``docs/headline.py`` as a module (the docs folder is not a package)."""
    sys.path.insert(0, str(ROOT / "docs"))
    try:
        import headline
    finally:
        sys.path.remove(str(ROOT / "docs"))
    return headline


def test_results_table_is_generated_from_the_comparison_json() -> None:
    headline = _headline()
    studies = headline.current(headline.comparisons())
    table = headline.headline_frame(studies).to_markdown(index=False)
    assert table in _section("Results")
    assert "-v1 " in table and "-v0 " not in table and "noise 0.1" in table


def test_the_docs_table_marks_rows_not_played_at_a_scale() -> None:
    """The results page's table holds every study; a row without runs at a scale reads n/a."""
    headline = _headline()
    frame = headline.headline_frame(headline.comparisons())
    shrinking = frame[frame["controller"] == "MPC (shrinking horizon)"]
    assert len(shrinking) and set(shrinking["success, noise 0.1"]) == {"n/a"}
    assert "n/a" not in set(shrinking["success, noise 0.01"])
    assert {"-v0", "-v1"} <= {env[-3:] for env in frame["env"]}


@pytest.mark.slow
def test_example_runs(capsys: pytest.CaptureFixture[str]) -> None:
    """The example block with a tiny training budget (one PPO rollout of 64 steps)."""
    code = re.search(r"```python\n(.*?)```", _section("Example"), re.S).group(1)
    assert "total_timesteps=200_000" in code
    code = code.replace("total_timesteps=200_000", "total_timesteps=64").replace(
        'PPO("MlpPolicy", env, seed=0)', 'PPO("MlpPolicy", env, seed=0, n_steps=64, batch_size=64)')
    exec(compile(code, str(README), "exec"), {})
    printed = capsys.readouterr().out
    assert re.search(r"success (True|False), time \d+\.\d\d s, optimum \d\.\d{3} s", printed)
