"""The first run after an install loads kernels compiled at install time (kernels/options.py, setup.py).

No timings here: the tests look at what numba did (the dispatchers' cache hits
and misses) and at the files.  BENCHMARKS.md has the times.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from stabmap.kernels import options, precompile

KERNELS = Path(options.__file__).parent

# Import stabmap.kernels from a copy of the folder alone (as setup.py does in the build tree).
_STUB = """
import sys, types
package = types.ModuleType("stabmap")
package.__path__ = [sys.argv[1]]
sys.modules["stabmap"] = package
"""


def _run(code: str, package: Path, env: dict) -> subprocess.CompletedProcess:
    out = subprocess.run([sys.executable, "-c", _STUB + textwrap.dedent(code), str(package)],
                         env=env, capture_output=True, text=True, timeout=600, check=False)
    assert out.returncode == 0, out.stderr
    return out


def _copy_kernels(package: Path) -> Path:
    (package / "kernels").mkdir(parents=True)
    for f in KERNELS.glob("*.py"):
        shutil.copyfile(f, package / "kernels" / f.name)
    return package / "kernels"


def _clean_env(**extra) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in {"NUMBA_CACHE_DIR", "STABMAP_CACHE_DIR", "STABMAP_NUMBA_CACHE"}}
    return dict(env, **extra)


@pytest.mark.skipif(not options.CACHE or os.environ.get("NUMBA_CACHE_DIR"), reason="needs stabmap's own kernel cache")
def test_a_cache_shipped_with_the_package_is_loaded_elsewhere_not_compiled(tmp_path):
    """What an install does: cache files made for one copy of the sources serve a copy at another path."""
    done = precompile.precompile()  # loads (or compiles, once) into this test run's cache
    package = tmp_path / "site-packages" / "stabmap"
    kernels = _copy_kernels(package)
    shipped = precompile.ship(done["cache_path"], kernels / "_cache")
    assert shipped.name == f"kernels-{options.DIGEST}" and list(shipped.glob("block.decide_block-*.nbi"))
    user = tmp_path / "user-cache"
    code = """
        import json
        from stabmap.kernels import options, precompile
        told = []
        options.set_compile_notice(told.append)
        done = precompile.precompile()
        print(json.dumps({"done": done, "told": told, "digest": options.DIGEST}))
    """
    first = json.loads(_run(code, package, _clean_env(STABMAP_CACHE_DIR=str(user))).stdout)
    assert first["digest"] == options.DIGEST
    assert first["done"]["loaded"] == len(precompile.signatures()) and first["done"]["compiled"] == 0, first
    assert first["told"] == []
    assert Path(first["done"]["cache_path"]).is_relative_to(user / f"kernels-{options.DIGEST}")
    assert list(Path(first["done"]["cache_path"]).glob("block.decide_block-*.nbi"))
    # sources that differ by one byte have another digest: nothing shipped is used
    with open(kernels / "status.py", "a") as f:
        f.write("\n")
    code = """
        import json
        from stabmap.kernels import options
        print(json.dumps({"digest": options.DIGEST, "shipped": options.SHIPPED.is_dir()}))
    """
    changed = json.loads(_run(code, package, _clean_env(STABMAP_CACHE_DIR=str(user))).stdout)
    assert changed["digest"] != options.DIGEST and not changed["shipped"]


def test_seed_copies_missing_functions_index_last_and_leaves_the_rest(tmp_path):
    shipped, target = tmp_path / "shipped", tmp_path / "target"
    shipped.mkdir()
    target.mkdir()
    for name in ["a-1.py311.nbi", "a-1.py311.1.nbc", "a-1.py311.2.nbc", "b-9.py311.nbi", "b-9.py311.1.nbc"]:
        (shipped / name).write_text(name)
    (target / "b-9.py311.nbi").write_text("numba's own")
    assert options.seed(target, shipped) == 3
    assert sorted(p.name for p in target.iterdir()) == ["a-1.py311.1.nbc", "a-1.py311.2.nbc", "a-1.py311.nbi", "b-9.py311.nbi"]
    assert (target / "b-9.py311.nbi").read_text() == "numba's own"
    assert options.seed(target, shipped) == 0
    assert options.seed(None, shipped) == 0 and options.seed(target, tmp_path / "none") == 0


def test_kernels_compile_and_run_when_the_cache_dir_cannot_be_written(tmp_path):
    blocker = tmp_path / "a-file"
    blocker.write_text("not a directory")
    code = """
        import json, warnings
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            from stabmap.kernels import block, dd, options
        told = []
        options.set_compile_notice(told.append)
        s, e = dd.two_sum(1.0, 1e-20)
        dd.two_sum(2.0, 1e-20)
        print(json.dumps({"s": s, "e": e, "path": block.decide_block.stats.cache_path, "told": told,
                          "warned": [str(w.message) for w in caught]}))
    """
    package = tmp_path / "stabmap"
    _copy_kernels(package)
    out = json.loads(_run(code, package, _clean_env(STABMAP_CACHE_DIR=str(blocker / "sub"))).stdout)
    assert (out["s"], out["e"]) == (1.0, 1e-20)
    assert out["path"] is None  # no on-disk cache: numba's __pycache__ fallback is not used either
    assert any("cannot write the kernel cache" in w for w in out["warned"])
    assert out["told"] == ["compiling kernels (once, ~20 s)"]  # once per process, not once per kernel
    assert not (package / "kernels" / "__pycache__").exists() or not list((package / "kernels" / "__pycache__").glob("*.nb?"))


@pytest.mark.skipif(not options.CACHE or os.environ.get("NUMBA_CACHE_DIR"), reason="needs stabmap's own kernel cache")
def test_atlas_refine_and_critical_call_only_the_precompiled_signatures():
    """A second signature would compile the whole kernel again on its first call (refine once passed read-only E)."""
    code = """
        import json
        import stabmap
        from stabmap.kernels import box_block, decide_block, linearise_block, nodes_box_block, precompile, roots_block
        from stabmap.scene.grid import resample
        scene = stabmap.example("paper-n3-fixed")
        small = resample(scene, **{a.name: 9 for a in scene.grid})
        stabmap.compute_atlas(small, progress=False, threads=1)
        stabmap.compute_refined(resample(scene, **{a.name: 17 for a in scene.grid}), progress=False, threads=1)
        stabmap.critical(small, "omega", progress=False, threads=1)  # boxes at nodes (spin-scaled)
        through_zero = stabmap.loads_scene(
            'support = "fixed"\\n[[bodies]]\\nm = 1.0\\nA = 0.02\\nC = 0.03\\nc = 0.1\\n[grid]\\nomega = { start = -2.0, stop = 2.0, num = 5 }\\n')
        stabmap.critical(through_zero, "omega", progress=False, threads=1)  # plain boxes at omega = 0
        stabmap.roots(small, **{a.name: a.values[0] for a in small.grid})  # query --roots
        viscous = stabmap.example("viscous-top-sphere")  # a viscous liquid's first-order rates
        stabmap.compute_atlas(resample(viscous, **{a.name: 9 for a in viscous.grid}), progress=False, threads=1)
        from stabmap.kernels.firstorder import first_order_block
        from stabmap.kernels.kreinbox import krein_box_block  # the cells' Krein boxes (omega x m_2)
        from stabmap.kernels.rates import rate_block  # growth rates from the pairs
        called = (decide_block.signatures + box_block.signatures + nodes_box_block.signatures + roots_block.signatures
                  + linearise_block.signatures + first_order_block.signatures + krein_box_block.signatures
                  + rate_block.signatures)
        print(json.dumps({"called": sorted(map(str, called)),
                          "precompiled": sorted(str(sig) for _, sig in precompile.signatures())}))
    """
    out = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=600,
                         check=False, env=_clean_env())
    assert out.returncode == 0, out.stderr
    seen = json.loads(out.stdout)
    assert seen["called"] == seen["precompiled"]


@pytest.mark.parametrize("given", [None, "3"])
def test_one_blas_thread_unless_the_user_chose(given):
    """The kernels run a block per core and call BLAS on small matrices: importing them sets one BLAS thread
    (as dask's Nanny does), before the BLAS library loads, and leaves a value the user set alone."""
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}
    if given:
        env["OPENBLAS_NUM_THREADS"] = given
    code = ("import os, sys; import stabmap.kernels; "
            "print(os.environ['OPENBLAS_NUM_THREADS'], os.environ['MKL_NUM_THREADS'])")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == [given or "1", "1"]
