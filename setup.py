"""The extension tippe._tippe for `pip install .`: configured and built by CMake (the project's one build), then copied where setuptools packs it."""
import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

SOURCE = Path(__file__).resolve().parent


class CMakeBuild(build_ext):
    """Builds the CMake target tippe_python in TIPPE_BUILD_DIR (default build/pip-python) against
    the interpreter that runs pip; TIPPE_CMAKE_ARGS adds options (e.g. -DTIPPE_WERROR=ON), ccache is
    used when installed (CCACHE_DIR as usual)."""

    def build_extension(self, ext):
        build = Path(os.environ.get("TIPPE_BUILD_DIR", SOURCE / "build" / "pip-python"))
        args = ["-DCMAKE_BUILD_TYPE=Release", f"-DPython3_EXECUTABLE={sys.executable}"]
        if shutil.which("ccache"):
            args.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
        args += os.environ.get("TIPPE_CMAKE_ARGS", "").split()
        subprocess.check_call(["cmake", "-S", str(SOURCE), "-B", str(build), *args])
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.check_call(["cmake", "--build", str(build), "--target", "tippe_python", "-j", jobs])
        built = sorted((build / "python" / "tippe").glob("_tippe*.so"))
        if not built:
            raise RuntimeError(f"{build}/python/tippe: no _tippe module after the build (is pybind11 installed?)")
        dest = Path(self.get_ext_fullpath(ext.name))
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[0], dest)


setup(ext_modules=[Extension("tippe._tippe", sources=[])], cmdclass={"build_ext": CMakeBuild})
