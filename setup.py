"""pip install --no-build-isolation . (docs/python.md): the streamrt package from the CMake build.

setuptools (Debian's python3-setuptools) copies the package's Python files
(engine/python/streamrt/) and, for its one extension, drives the CMake build: configures the
build folder when it has not been configured yet (Release, for this interpreter), builds the
target streamrt_python (the extension and the modules it loads on first use), and copies the
extension and those modules (build/lib/streamrt/libstreamrt_*.so) into the package, where the
engine looks for them first (core/module_loader.h).

The build folder is build/, the one scripts/build.sh and scripts/render.sh use (a module
built there already is only checked), or $STREAMRT_BUILD_DIR.
"""
import os
import pathlib
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent
BUILD = pathlib.Path(os.path.abspath(os.environ.get("STREAMRT_BUILD_DIR") or ROOT / "build"))


def cmake_version():
    """The project's version, from CMakeLists.txt's project() (one place for it)."""
    return re.search(r"project\(streamrt VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text()).group(1)


def cache_value(name):
    """A variable of the build folder's CMakeCache.txt, or None."""
    for line in (BUILD / "CMakeCache.txt").read_text().splitlines():
        if line.startswith(name + ":"):
            return line.split("=", 1)[1]
    return None


class CMakeBuild(build_ext):
    """The extension streamrt._native and the modules, built by CMake."""

    def build_extension(self, ext):
        if not (BUILD / "CMakeCache.txt").exists():
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(BUILD), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                            "-DPython3_EXECUTABLE=" + getattr(sys, "_base_executable", sys.executable)], check=True)
        refused = {"CMAKE_BUILD_TYPE": "Release", "STREAMRT_BUILD_PYTHON": "ON", "STREAMRT_SANITIZE": ""}
        for name, wanted in refused.items():
            if (cache_value(name) or "") != wanted:
                sys.exit("streamrt: %s has %s=%s; the package needs %s=%s (set STREAMRT_BUILD_DIR to another "
                         "build folder)" % (BUILD, name, cache_value(name), name, wanted or "''"))
        subprocess.run(["cmake", "--build", str(BUILD), "--target", "streamrt_python"], check=True)
        package = BUILD / "python" / "streamrt"
        native = package / ("_native" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not native.exists():
            sys.exit("streamrt: %s holds no %s: that build is for another Python (%s); set STREAMRT_BUILD_DIR to a "
                     "new folder to build one for %s" % (BUILD, native.name, cache_value("Python3_EXECUTABLE"),
                                                         sys.executable))
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(native, target)
        for stale in target.parent.glob("libstreamrt_*.so"):  # an earlier build's, kept by setuptools
            stale.unlink()
        for module in sorted((BUILD / "lib" / "streamrt").glob("libstreamrt_*.so")):
            shutil.copyfile(module, target.parent / module.name)


# setuptools' own folders (build/lib.*, bdist.*, the egg-info) go inside the CMake build
# folder, not beside it in the repository.
(BUILD / "setuptools").mkdir(parents=True, exist_ok=True)
setup(
    version=cmake_version(),
    # Here rather than in pyproject.toml, where setuptools 66 calls [tool.setuptools] beta.
    packages=["streamrt"],
    package_dir={"streamrt": "engine/python/streamrt"},
    package_data={"streamrt": ["__init__.pyi", "py.typed"]},
    ext_modules=[Extension("streamrt._native", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": str(BUILD / "setuptools")}, "egg_info": {"egg_base": str(BUILD / "setuptools")}},
)
