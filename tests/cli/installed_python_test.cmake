# The installed Python package on its own: installs the build in BUILD_DIR into a scratch prefix outside the source
# and build trees, then imports redres from <prefix>/PYTHON_DIR with PYTHON (the interpreter it was built for), from
# a scratch working directory, and runs the installed paper scenario through it. Checks that the module came from
# the prefix and that its run matches the installed CLI's. The scratch directory is removed when the test passes.
set(SCRATCH_NAME installed-python)
include(${CMAKE_CURRENT_LIST_DIR}/scratch_install.cmake)
file(WRITE ${work}/check.py [=[
import json, pathlib, subprocess, sys
import redres
prefix = pathlib.Path(sys.argv[1]).resolve()
assert pathlib.Path(redres.__file__).resolve().is_relative_to(prefix), redres.__file__
config = prefix / "share/redres/configs/paper_r_fast.toml"
result = redres.Scenario.load(config).run()
subprocess.run([str(prefix / "bin/redres"), "run", str(config), "--out", "cli", "--quiet"], check=True)
want = json.loads(pathlib.Path("cli/summary.json").read_text())
assert result.final_theta.tolist() == want["final_theta"], (result.final_theta, want["final_theta"])
print("installed redres from", redres.__file__)
]=])
execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${prefix}/${PYTHON_DIR} ${PYTHON} ${work}/check.py ${prefix}
                WORKING_DIRECTORY ${work} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the installed Python package failed (${rc}) ${RUN_FAILURE_NOTE}:\n${out}\n${err}")
endif()
message(STATUS "${out}")
file(REMOVE_RECURSE ${work})
