"""Kernels cached on disk (mdi_envs/_kernel_cache.py): reuse, invalidation and concurrency.

The cross-process tests run ``tests/kernel_cache/probe.py`` (a 1-DOF oscillator defined outside
the package, stepped by the single, batched and in-place kernels) in fresh interpreters with
their own cache root, and read numba's cache hits (loads) and misses (compiles).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numba import njit
from numba.core import config

import mdi_envs
from mdi_envs import _kernel_cache
from mdi_envs._kernel_cache import CACHE_DIR_VARIABLE, PackageCacheLocator, freeze, source_digest

HERE = Path(__file__).resolve().parent / "kernel_cache"
PROBE = HERE / "probe.py"
OSCILLATOR = HERE / "oscillator.py"
pytestmark = pytest.mark.skipif(config.DISABLE_JIT, reason="nothing is cached without the JIT")


def _environment(cache: Path, python_path: Path | None = None) -> dict[str, str]:
    environment = {**os.environ, CACHE_DIR_VARIABLE: str(cache)}
    if python_path is not None:
        environment["PYTHONPATH"] = str(python_path)
    return environment


def _probe(cache: Path, model: Path, *arguments: str, python_path: Path | None = None) -> dict:
    completed = subprocess.run(
        [sys.executable, str(PROBE), str(model), *arguments], capture_output=True, text=True,
        env=_environment(cache, python_path), timeout=600, check=False,
    )
    assert completed.returncode == 0, completed.stderr[-3000:]
    return json.loads(completed.stdout.strip().splitlines()[-1])


def _model_variant(tmp_path: Path, name: str, old: str, new: str) -> Path:
    source = OSCILLATOR.read_text()
    assert old in source
    path = tmp_path / name
    path.write_text(source.replace(old, new))
    return path


def _package_solvers_only(cache: Path) -> None:
    """Copy into ``cache`` the package's own compiled functions from this process's cache.

    numba's files of the package modules (the solvers; none if that cache is cold), not those
    of any generated kernel module (``kernels_*``): the probes still compile every kernel they
    count, and are spared recompiling the solvers those kernels call.
    """
    source = _kernel_cache.digest_dir() / "numba"
    target = cache / _kernel_cache.digest_dir().name / "numba"
    target.mkdir(parents=True)
    if source.is_dir():
        for folder in source.iterdir():
            if folder.is_dir() and not folder.name.startswith("kernels_"):
                shutil.copytree(folder, target / folder.name)


@pytest.fixture(scope="module")
def shared_cache(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, list[dict]]:
    """A cache root without kernels filled by two probes started together (both compile)."""
    cache = tmp_path_factory.mktemp("kernel_cache")
    _package_solvers_only(cache)
    processes = [
        subprocess.Popen([sys.executable, str(PROBE), str(OSCILLATOR)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=_environment(cache))
        for _ in range(2)
    ]
    results = []
    for process in processes:
        out, err = process.communicate(timeout=900)
        assert process.returncode == 0, err[-3000:]
        results.append(json.loads(out.strip().splitlines()[-1]))
    return cache, results


# ---- in-process: what freeze writes -------------------------------------------------------


def _make_kernels(scale: float) -> dict:
    offsets = (1.0, np.float64(0.5), np.inf)

    @njit(inline="always")
    def shift(x):  # noqa: ANN001, ANN202
        return x + offsets[1]

    @njit
    def scaled(x):  # noqa: ANN001, ANN202
        return shift(x) * scale + shift(0.0) + min(offsets[2], 7.0)

    @njit
    def twice(x):  # noqa: ANN001, ANN202
        return scaled(x) + scaled(x)

    return {"scaled": scaled, "twice": twice}


def test_freeze_computes_what_the_closures_compute(tmp_path: Path,
                                                   monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(CACHE_DIR_VARIABLE, str(tmp_path))
    closures = _make_kernels(2.0)
    frozen = freeze("test_scale", closures)
    assert frozen["scaled"](3.0) == closures["scaled"](3.0) == 3.5 * 2.0 + 0.5 + 7.0
    assert frozen["twice"](1.0) == closures["twice"](1.0)
    path = Path(sys.modules[frozen["twice"].py_func.__module__].__file__)
    assert path.is_relative_to(tmp_path)
    source = path.read_text()
    assert source.count("def scaled") == 1 and source.count("def shift") == 1  # copied once
    assert "inf" in source and "np.float64(0.5)" in source


def test_a_changed_constant_is_a_new_module(tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(CACHE_DIR_VARIABLE, str(tmp_path))
    two, three = freeze("test_scale", _make_kernels(2.0)), freeze("test_scale", _make_kernels(3.0))
    assert two["scaled"](1.0) == 1.5 * 2.0 + 7.5
    assert three["scaled"](1.0) == 1.5 * 3.0 + 7.5
    assert two["scaled"].py_func.__module__ != three["scaled"].py_func.__module__
    again = freeze("test_scale", _make_kernels(2.0))
    assert again["scaled"] is two["scaled"]  # same source: the same module


def test_an_unwritable_cache_falls_back_with_a_warning(tmp_path: Path,
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    blocked = tmp_path / "file"
    blocked.write_text("a file, not a folder")
    monkeypatch.setenv(CACHE_DIR_VARIABLE, str(blocked / "cache"))
    monkeypatch.setattr(_kernel_cache.tempfile, "gettempdir", lambda: str(tmp_path))
    with pytest.warns(RuntimeWarning, match="cannot write the kernel cache"):
        frozen = freeze("test_fallback", _make_kernels(5.0))
    assert frozen["scaled"](1.0) == 1.5 * 5.0 + 7.5
    assert Path(sys.modules[frozen["scaled"].py_func.__module__].__file__).is_relative_to(
        tmp_path)


def test_freeze_refuses_values_it_cannot_write(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv(CACHE_DIR_VARIABLE, str(tmp_path))
    table = np.arange(3.0)

    @njit
    def lookup(i):  # noqa: ANN001, ANN202
        return table[i]

    with pytest.raises(TypeError, match="'table' \\(ndarray\\)"):
        freeze("test_array", {"lookup": lookup})


def test_freeze_under_disabled_jit_returns_the_functions(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(config, "DISABLE_JIT", True)
    kernels = _make_kernels(2.0)
    assert freeze("test_scale", kernels) == kernels


def test_digest_follows_every_package_source_and_the_version(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    copy = tmp_path / "mdi_envs"
    shutil.copytree(_kernel_cache.PACKAGE_DIR, copy,
                    ignore=shutil.ignore_patterns("__pycache__"))
    assert source_digest(copy) == source_digest()
    lemke = copy / "solvers" / "lcp" / "lemke.py"
    lemke.write_text(lemke.read_text() + "\n# an edit in a callee's module\n")
    assert source_digest(copy) != source_digest()
    monkeypatch.setattr(_kernel_cache, "__version__", "99.0")
    bumped = source_digest()
    monkeypatch.undo()
    assert bumped != source_digest()


def test_the_locator_takes_package_files_only() -> None:
    from mdi_envs.solvers.lcp.lemke import lemke_kernel

    locator = PackageCacheLocator.from_function(lemke_kernel.py_func,
                                                lemke_kernel.py_func.__code__.co_filename)
    assert locator is not None
    assert locator.get_source_stamp() == _kernel_cache.source_digest()
    assert Path(locator.get_cache_path()).is_relative_to(_kernel_cache.digest_dir())
    assert PackageCacheLocator.from_function(_make_kernels, __file__) is None
    assert mdi_envs.__version__ == _kernel_cache.__version__


# ---- across processes (slow: they compile into caches without kernels) ---------------


@pytest.mark.slow
def test_processes_compiling_together_agree(shared_cache: tuple[Path, list[dict]]) -> None:
    _, results = shared_cache
    assert any(result["misses"] == 3 for result in results)  # no kernel was in the cache
    for result in results:
        assert {key: value for key, value in result.items() if key not in ("hits", "misses")} \
            == {key: value for key, value in results[0].items()
                if key not in ("hits", "misses")}
        assert result["batch_q"] == [result["q"]] * 3 and result["in_place_q"] == result["q"]


@pytest.mark.slow
def test_a_new_process_loads_instead_of_compiling(shared_cache: tuple[Path, list[dict]]) -> None:
    cache, results = shared_cache
    warm = _probe(cache, OSCILLATOR)
    assert warm["misses"] == 0 and warm["hits"] == 3
    assert warm["q"] == results[0]["q"] and warm["u"] == results[0]["u"]


@pytest.mark.slow
def test_an_edited_model_recompiles_with_its_new_equations(
        shared_cache: tuple[Path, list[dict]], tmp_path: Path) -> None:
    cache, results = shared_cache
    edited = _model_variant(tmp_path, "oscillator.py", "-p.stiffness * q[0]",
                            "-2.0 * p.stiffness * q[0]")
    after_edit = _probe(cache, edited)
    assert after_edit["misses"] == 3 and after_edit["hits"] == 0
    assert after_edit["q"] != results[0]["q"]
    # the edit doubles the stiffness: the unedited model with k = 8 (its cached kernels)
    doubled = _probe(cache, OSCILLATOR, "8.0")
    assert doubled["misses"] == 0
    assert (doubled["q"], doubled["u"]) == (after_edit["q"], after_edit["u"])


@pytest.mark.slow
def test_an_edited_package_recompiles_with_its_new_code(
        shared_cache: tuple[Path, list[dict]], tmp_path: Path) -> None:
    cache, results = shared_cache
    shutil.copytree(_kernel_cache.PACKAGE_DIR, tmp_path / "mdi_envs",
                    ignore=shutil.ignore_patterns("__pycache__"))
    midpoint = tmp_path / "mdi_envs" / "stepping" / "_midpoint.py"
    text = midpoint.read_text()
    assert "RESOLVED_INERTIA_FRACTION = 0.9\n" in text
    # every step now counts as under-resolved (status INACCURATE): visible new behaviour
    midpoint.write_text(text.replace("RESOLVED_INERTIA_FRACTION = 0.9\n",
                                     "RESOLVED_INERTIA_FRACTION = 2.0\n"))
    edited = _probe(cache, OSCILLATOR, python_path=tmp_path)
    assert results[0]["status"] == "CONVERGED"
    assert edited["status"] == "INACCURATE" and edited["misses"] == 3
    assert edited["q"] == results[0]["q"]  # the same step, judged differently


@pytest.mark.slow
def test_subproc_vec_env_workers_compiling_together(
        shared_cache: tuple[Path, list[dict]]) -> None:
    # the package's solver kernels are in the shared cache; the ball's step and scene kernels
    # are not: both workers compile them at once; then one plain process loads what they wrote
    cache, _ = shared_cache
    assert not list(cache.glob("*/kernels/mdi_envs_kernels_scene_BouncingBall*.py"))
    workers = (
        "import numpy as np, mdi_envs\n"
        "from stable_baselines3.common.env_util import make_vec_env\n"
        "from stable_baselines3.common.vec_env import SubprocVecEnv\n"
        "if __name__ == '__main__':\n"
        "    env = make_vec_env('mdi_envs:mdi_envs/BouncingBall-v0', n_envs=2, seed=0,\n"
        "                       vec_env_cls=SubprocVecEnv)\n"
        "    env.reset()\n"
        "    obs, *_ = env.step(np.zeros((2, 1), np.float32))\n"
        "    env.close()\n"
        "    print(repr(obs.tolist()))\n"
    )
    one_process = (  # the same two copies (seeds 0 and 1, as make_vec_env seeds them)
        "import gymnasium as gym, numpy as np, mdi_envs\n"
        "obs = []\n"
        "for seed in (0, 1):\n"
        "    env = gym.make('mdi_envs/BouncingBall-v0')\n"
        "    env.reset(seed=seed)\n"
        "    obs.append(env.step(np.zeros(1, np.float32))[0])\n"
        "print(repr(np.array(obs).tolist()))\n"
    )
    runs = [subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                           env=_environment(cache), timeout=900, check=False)
            for script in (workers, one_process)]
    for run in runs:
        assert run.returncode == 0, run.stderr[-3000:]
    assert runs[0].stdout == runs[1].stdout  # the second run, from the cache, agrees
    assert list(cache.glob("*/kernels/mdi_envs_kernels_scene_BouncingBall*.py"))
