"""Build hook: ship the JSBSim root (aircraft/ and systems/) inside the wheel.

JSBSim looks for ``aircraft/`` and ``systems/`` under one root directory. In a checkout they
sit at the repository's top level; in an installed wheel they are copied to
``bioflex_jsb/jsbsim_root/`` so that ``bioflex_jsb.runtime.fdm`` finds them there.
All other metadata is in pyproject.toml.
"""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

JSBSIM_DIRS = ("aircraft", "systems")


class BuildPyWithJSBSimRoot(build_py):
    """build_py that also copies the JSBSim root into the built package."""

    def run(self):
        super().run()
        here = Path(__file__).resolve().parent
        target = Path(self.build_lib) / "bioflex_jsb" / "jsbsim_root"
        for name in JSBSIM_DIRS:
            dest = target / name
            if dest.exists():
                shutil.rmtree(dest)
            shutil.copytree(here / name, dest, ignore=shutil.ignore_patterns("__pycache__"))


setup(cmdclass={"build_py": BuildPyWithJSBSimRoot})
