"""Builds the extension with the project's CMake build (pyproject.toml; docs/PYTHON.md, Install).

The build folder is $APPARENT_BUILD_DIR, else build/ in the repository (shared with the
command-line build, so nothing is compiled twice); the package's Python files and the extension
_apparent are taken from BUILD/python/apparent."""
import glob
import os
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Distribution, setup
from setuptools.command.build_py import build_py

ROOT = os.path.dirname(os.path.abspath(__file__))
BUILD = os.environ.get("APPARENT_BUILD_DIR") or os.path.join(ROOT, "build")
# setuptools' own files (egg-info, build/lib) go to BUILD/setuptools, not into the source tree.
SETUPTOOLS_DIR = os.path.join(BUILD, "setuptools")
os.makedirs(SETUPTOOLS_DIR, exist_ok=True)


class BuildWithCMake(build_py):
    def run(self):
        super().run()
        build = BUILD
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            subprocess.check_call(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
                                   "-DPython3_EXECUTABLE=" + sys.executable])
        subprocess.check_call(["cmake", "--build", build, "--target", "apparent_python", "-j", str(os.cpu_count() or 1)])
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        built = glob.glob(os.path.join(build, "python", "apparent", "_apparent*" + suffix))
        if not built:
            sys.exit("setup.py: %s/python/apparent has no _apparent%s (the build's Python is not this one, %s: "
                     "configure it with -DPython3_EXECUTABLE=%s)" % (build, suffix, sys.version.split()[0], sys.executable))
        target = os.path.join(self.build_lib, "apparent")
        os.makedirs(target, exist_ok=True)
        shutil.copy2(built[0], target)
        three = os.path.join(build, "python", "apparent", "three")  # the notebooks' view, when built
        if os.path.isdir(three):
            shutil.copytree(three, os.path.join(target, "three"), dirs_exist_ok=True)


class BinaryDistribution(Distribution):
    def has_ext_modules(self):
        return True


setup(packages=["apparent"], package_dir={"apparent": "python/apparent"}, cmdclass={"build_py": BuildWithCMake},
      distclass=BinaryDistribution,
      options={"egg_info": {"egg_base": os.path.relpath(SETUPTOOLS_DIR, ROOT)},
               "build": {"build_base": os.path.join(SETUPTOOLS_DIR, "build")}})
