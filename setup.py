"""Build step: compile the kernels into the package, so the first run after ``pip install .`` loads them.

``pip install .`` builds the wheel on the machine it installs on, so numba's
cache files, keyed by CPU, fit that machine (docs/speed.md, "First run").  The
kernels are compiled in a fresh interpreter from the built copy of the package
(``python -m stabmap.kernels.precompile --ship``); a failure only leaves the
compilation to the first run.  STABMAP_PRECOMPILE=0 skips it, e.g. for a wheel
meant for other machines; editable installs skip it too.
"""

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

# Import stabmap.kernels from the build tree without running stabmap/__init__.py, whose
# dependencies the build environment does not have.
_PRECOMPILE = """
import sys, types
package = types.ModuleType("stabmap")
package.__path__ = [sys.argv[1]]
sys.modules["stabmap"] = package
from stabmap.kernels import precompile
precompile.main(["--ship", sys.argv[2]])
"""


class BuildPyWithKernelCache(build_py):
    def run(self):
        super().run()
        if getattr(self, "editable_mode", False) or os.environ.get("STABMAP_PRECOMPILE", "1").lower() in {"0", "false", "no", "off"}:
            return
        package = Path(self.build_lib) / "stabmap"
        shutil.rmtree(package / "kernels" / "_cache", ignore_errors=True)  # an earlier build's, maybe of other sources
        with tempfile.TemporaryDirectory() as tmp:
            env = dict(os.environ, NUMBA_CACHE_DIR=tmp, STABMAP_NUMBA_CACHE="1")
            done = subprocess.run([sys.executable, "-c", _PRECOMPILE, str(package), str(package / "kernels" / "_cache")],
                                  env=env, capture_output=True, text=True, check=False)
        if done.returncode:
            print(f"stabmap: kernels not precompiled, the first run compiles them:\n{done.stderr[-2000:]}", file=sys.stderr)
        else:
            print(done.stdout, end="")


setup(cmdclass={"build_py": BuildPyWithKernelCache})
