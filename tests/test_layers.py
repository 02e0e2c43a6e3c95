"""The import structure: the layer contract of ``pyproject.toml`` holds, no module import cycle.

Both read the import graph that grimp builds statically from the source (every import
statement, also those inside functions; type-only imports under ``TYPE_CHECKING`` excepted).
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from pathlib import Path

import grimp
import numpy as np
import pytest
import scipy.sparse as sp
from importlinter.cli import lint_imports
from scipy.sparse.csgraph import connected_components

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("mdi_envs", "optimal", "baselines", "benchmarks")


def import_cycles(*packages: str) -> list[list[str]]:
    """The module sets that import each other in a circle (strongly connected, size > 1)."""
    graph = grimp.build_graph(*packages, exclude_type_checking_imports=True, cache_dir=None)
    modules = sorted(graph.modules)
    index = {module: i for i, module in enumerate(modules)}
    edges = [(index[module], index[imported]) for module in modules
             for imported in graph.find_modules_directly_imported_by(module)]
    rows, cols = zip(*edges, strict=True) if edges else ((), ())
    adjacency = sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(len(modules),) * 2)
    _, labels = connected_components(adjacency, connection="strong")
    components = [[modules[i] for i in np.flatnonzero(labels == label)]
                  for label in np.unique(labels)]
    return [members for members in components if len(members) > 1]


# A cycle across packages would break the layer contract, so each package is checked alone.
@pytest.mark.parametrize("package", ["mdi_envs", "optimal", "benchmarks", "baselines"])
def test_no_import_cycle(package: str) -> None:
    assert import_cycles(package) == []


def test_the_layer_contract_is_kept(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(ROOT)
    assert lint_imports(config_filename=str(ROOT / "pyproject.toml"), no_cache=True,
                        no_logo=True) == 0  # fmt: skip


@pytest.fixture
def tangled_package(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[str]:
    """A package: a -> b -> c -> a (c's inside a function); d -> a, d -> e, e -> d type-only."""
    package = tmp_path / "tangled"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "a.py").write_text("from tangled import b\n")
    (package / "b.py").write_text("import tangled.c\n")
    (package / "c.py").write_text("def f():\n    from tangled.a import x\n")
    (package / "d.py").write_text("import tangled.a\nimport tangled.e\n")
    (package / "e.py").write_text("from typing import TYPE_CHECKING\n"
                                  "if TYPE_CHECKING:\n    import tangled.d\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    yield "tangled"
    sys.modules.pop("tangled", None)


def test_cycles_are_found(tangled_package: str) -> None:
    assert import_cycles(tangled_package) == [["tangled.a", "tangled.b", "tangled.c"]]
