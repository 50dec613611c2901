"""Builds the redres Python package for pip through the project's own CMake (pyproject.toml, docs/python.md).

`pip install --no-build-isolation .` (or `--target DIR`, or into a venv) runs build_ext below, which
  1. configures a CMake build directory with the tests, benchmarks, examples and fuzzers off and the Python module on,
     for the interpreter that runs pip (or reuses the directory named by REDRES_CMAKE_BUILD_DIR, as it is configured);
  2. builds the target redres_python (the extension redres._redres and the library libredres.so it links);
  3. copies the extension and the library (under its SONAME, libredres.so.<major>) into the package, and sets the
     extension's RPATH to $ORIGIN so that the installed module finds the library beside it.
The pure-Python files (framework/python/redres/: __init__.py, the stub _redres.pyi and py.typed) are copied by
setuptools itself. The version is CMakeLists.txt's project(VERSION), written nowhere else.
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


def project_version():
    """The VERSION of project(redres ...) in the top-level CMakeLists.txt."""
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"project\(\s*redres\s+VERSION\s+([0-9]+(?:\.[0-9]+)*)", text)
    if match is None:
        raise RuntimeError(f"{ROOT / 'CMakeLists.txt'}: no `project(redres VERSION x.y.z ...)` to read the version from")
    return match.group(1)


def run(command, what):
    print("redres setup.py:", " ".join(str(c) for c in command), flush=True)
    try:
        subprocess.run([str(c) for c in command], check=True)
    except FileNotFoundError as e:
        raise RuntimeError(f"{what}: {e.filename} not found (scripts/install_deps.sh installs cmake and the "
                           "compiler)") from e
    except subprocess.CalledProcessError as e:
        raise RuntimeError(f"{what} failed with exit code {e.returncode} (its output is above)") from e


class CMakeBuild(build_ext):
    """Builds redres._redres with CMake instead of compiling sources itself."""

    def build_extension(self, ext):
        reused = os.environ.get("REDRES_CMAKE_BUILD_DIR")
        if reused:
            build_dir = pathlib.Path(reused).resolve()
            if not (build_dir / "CMakeCache.txt").is_file():
                raise RuntimeError(f"REDRES_CMAKE_BUILD_DIR={reused}: no CMakeCache.txt there; name a directory that "
                                   "CMake has configured (e.g. build/release), or unset it to configure a new one")
        else:
            build_dir = pathlib.Path(self.build_temp).resolve() / "cmake"
            run(["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release", "-DREDRES_BUILD_TESTS=OFF",
                 "-DREDRES_BUILD_BENCHMARKS=OFF", "-DREDRES_BUILD_EXAMPLES=OFF", "-DREDRES_BUILD_FUZZERS=OFF",
                 "-DREDRES_BUILD_PYTHON=ON", f"-DPython_EXECUTABLE={sys.executable}"], "configuring redres")
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(self.parallel or os.cpu_count() or 1)
        run(["cmake", "--build", build_dir, "--target", "redres_python", "-j", jobs], "building redres_python")

        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        extension = build_dir / "python" / "redres" / f"_redres{suffix}"
        if not extension.is_file():
            found = sorted(p.name for p in (build_dir / "python" / "redres").glob("_redres*"))
            raise RuntimeError(f"{extension} was not built: the CMake build in {build_dir} is for another Python "
                               f"(it has {found or 'no extension'}; this pip runs {sys.executable}, which loads "
                               f"'_redres{suffix}'). Configure it with -DPython_EXECUTABLE={sys.executable}")
        major = project_version().split(".")[0]
        library = build_dir / "lib" / f"libredres.so.{major}"
        if not library.exists():
            raise RuntimeError(f"{library} is missing: the CMake build in {build_dir} has no redres library")

        package = pathlib.Path(self.get_ext_fullpath(ext.name)).parent
        package.mkdir(parents=True, exist_ok=True)
        target = package / extension.name
        shutil.copyfile(extension, target)
        shutil.copyfile(library.resolve(), package / library.name)  # the file itself, under the SONAME it is linked by
        # The extension's build RPATH names the build tree: the installed one looks beside itself instead.
        run(["cmake", f"-DFILE={target}", "-P", ROOT / "cmake" / "set_rpath_origin.cmake"], "setting the RPATH")


# setuptools' own files go under the (ignored) build/ directory, not beside the sources.
PIP_BUILD = ROOT / "build" / "pip"
PIP_BUILD.mkdir(parents=True, exist_ok=True)

setup(
    version=project_version(),
    packages=["redres"],
    package_dir={"redres": "framework/python/redres"},
    package_data={"redres": ["py.typed", "_redres.pyi"]},
    ext_modules=[Extension("redres._redres", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": str(PIP_BUILD)}, "egg_info": {"egg_base": str(PIP_BUILD)}},
)
