# setuptools' side of `pip install .` (pyproject.toml): the package's Python files from
# python/buckle and its compiled module buckle._core built by CMake — the target buckle_python of
# the CMake build in $BUCKLE_BUILD_DIR (default: build, the README's build directory; configured
# here for this interpreter when it has no CMakeCache.txt), so an existing build is reused and only
# what changed is compiled. The version is the CMake project's.
import importlib.machinery
import os
import pathlib
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


def version():
    match = re.search(r"project\(buckle VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    if not match:
        sys.exit("setup.py: no `project(buckle VERSION x.y.z)` in CMakeLists.txt")
    return match[1]


def build_directory():
    return pathlib.Path(os.environ.get("BUCKLE_BUILD_DIR", ROOT / "build")).resolve()


class CMakeBuild(build_ext):
    """Builds buckle._core with CMake and copies it where setuptools packs it."""

    def build_extension(self, ext):
        build = build_directory()
        cmake = shutil.which("cmake")
        if cmake is None:
            sys.exit("setup.py: cmake is needed to build buckle's compiled module (Debian: apt-get install cmake)")
        if not (build / "CMakeCache.txt").exists():
            subprocess.run([cmake, "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                            "-DBUCKLE_BUILD_PYTHON=ON", "-DBUCKLE_BUILD_TESTS=OFF", "-DBUCKLE_BUILD_BENCHMARKS=OFF",
                            f"-DPython3_EXECUTABLE={sys.executable}"], check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.run([cmake, "--build", str(build), "--target", "buckle_python", "-j", jobs], check=True)
        built = [p for p in (build / "python" / "buckle").glob("_core*") if p.suffix in (".so", ".pyd")]
        suffixes = importlib.machinery.EXTENSION_SUFFIXES
        usable = [p for p in built if any(p.name == "_core" + s for s in suffixes)]
        if not usable:
            sys.exit(f"setup.py: {build} holds no buckle._core for this Python ({sys.executable}, module suffixes "
                     f"{', '.join(suffixes)}; found {', '.join(p.name for p in built) or 'none'}): it was configured "
                     "for another interpreter. Set BUCKLE_BUILD_DIR to a new directory to build one for this Python.")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(usable[0], target)


build_directory().mkdir(parents=True, exist_ok=True)  # egg_info writes there first
setup(
    version=version(),
    packages=["buckle"],
    package_dir={"buckle": "python/buckle"},
    ext_modules=[Extension("buckle._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # setuptools' own intermediate files in the CMake build directory, not in the checkout
    options={"build": {"build_base": str(build_directory() / "setuptools")},
             "egg_info": {"egg_base": str(build_directory())}},
    zip_safe=False,
)
