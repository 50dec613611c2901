# `pip install .` of the repository (pyproject.toml, setup.py), offline and without build isolation, as a user does
# it on Debian: once with --target into a scratch directory, once into a scratch venv (--system-site-packages, for
# Debian's numpy). REDRES_CMAKE_BUILD_DIR=BUILD_DIR makes setup.py reuse this build (only the target redres_python
# is brought up to date), so the test takes seconds. Each installed package is then imported with PYTHON (the venv's
# python for the venv) from a scratch working directory outside the source and build trees, and checked: the module,
# its extension and libredres.so come from the install, the version is CMake's, the typing files are there, and a robot
# loads and gives the kinematics the build's module gives. The scratch directory is removed when the test passes.
if(DEFINED ENV{TMPDIR} AND IS_DIRECTORY "$ENV{TMPDIR}")
  set(tmp "$ENV{TMPDIR}")
else()
  set(tmp /tmp)
endif()
string(RANDOM LENGTH 8 tag)
file(REAL_PATH ${tmp}/redres-pip-install-${tag} work)
file(REMOVE_RECURSE ${work})
file(MAKE_DIRECTORY ${work})
set(RUN_FAILURE_NOTE "(scratch directory kept: ${work})")

# pip offline (no index), without its cache or version check, and building against this build directory.
set(pip_env PIP_NO_INDEX=1 PIP_NO_CACHE_DIR=1 PIP_DISABLE_PIP_VERSION_CHECK=1 REDRES_CMAKE_BUILD_DIR=${BUILD_DIR})

function(checked what)
  execute_process(COMMAND ${ARGN} WORKING_DIRECTORY ${work} RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}) ${RUN_FAILURE_NOTE}:\n${out}\n${err}")
  endif()
  message(STATUS "${what}: ok")
endfunction()

file(WRITE ${work}/check.py [=[
import json, pathlib, re, subprocess, sys
where, source, build_python = pathlib.Path(sys.argv[1]).resolve(), pathlib.Path(sys.argv[2]), sys.argv[3]
import numpy as np
import redres
package = pathlib.Path(redres.__file__).resolve().parent
assert package.is_relative_to(where), f"redres imported from {package}, not from the install in {where}"
assert pathlib.Path(redres._redres.__file__).resolve().parent == package, redres._redres.__file__
# The extension found libredres.so beside it (its RPATH), not the build's.
maps = pathlib.Path("/proc/self/maps").read_text()
libs = {line.split()[-1] for line in maps.splitlines() if "libredres.so" in line}
assert libs and all(pathlib.Path(lib).parent == package for lib in libs), libs
assert (package / "py.typed").is_file() and (package / "_redres.pyi").is_file(), sorted(package.iterdir())
version = re.search(r"project\(\s*redres\s+VERSION\s+([0-9.]+)", (source / "CMakeLists.txt").read_text()).group(1)
assert redres.__version__ == version, (redres.__version__, version)
robot = redres.Robot.load(source / "robots/franka_panda.toml")
k = robot.kinematics(robot.home)
assert k.J.shape == (3, 7) and k.w > 0
# The same numbers as the build tree's module.
code = ("import json, sys, redres; r = redres.Robot.load(sys.argv[1]); k = r.kinematics(r.home); "
        "print(json.dumps([k.f.tolist(), k.J.tolist(), k.w]))")
built = subprocess.run([sys.executable, "-c", code, str(source / "robots/franka_panda.toml")], check=True,
                       capture_output=True, text=True, env={"PYTHONPATH": build_python}).stdout
assert json.loads(built) == [k.f.tolist(), k.J.tolist(), k.w]
print("pip-installed redres", redres.__version__, "from", package)
]=])

# 1. pip install --target DIR .
checked("pip install --target"
        ${CMAKE_COMMAND} -E env ${pip_env} ${PYTHON} -m pip install --no-build-isolation --target ${work}/target
        ${SOURCE_DIR})
checked("import from --target"
        ${CMAKE_COMMAND} -E env PYTHONPATH=${work}/target PYTHONDONTWRITEBYTECODE=1
        ${PYTHON} ${work}/check.py ${work}/target ${SOURCE_DIR} ${BUILD_DIR}/python)

# 2. pip install . into a venv (the venv without pip of its own: the system pip installs into it).
checked("python3 -m venv" ${PYTHON} -m venv --system-site-packages --without-pip ${work}/venv)
checked("pip install into the venv"
        ${CMAKE_COMMAND} -E env ${pip_env} ${PYTHON} -m pip --python ${work}/venv/bin/python install
        --no-build-isolation ${SOURCE_DIR})
checked("import from the venv"
        ${CMAKE_COMMAND} -E env --unset=PYTHONPATH PYTHONDONTWRITEBYTECODE=1
        ${work}/venv/bin/python ${work}/check.py ${work}/venv ${SOURCE_DIR} ${BUILD_DIR}/python)

file(REMOVE_RECURSE ${work})
