"""The typing of the redres package (ctest python.typing): with the build's package (argument 1, e.g.
build/release/python) on mypy's path,
  1. mypy accepts uses_api.py, a small program that uses the API (and so the stub _redres.pyi and the annotations of
     redres/__init__.py type-check);
  2. mypy rejects misuses_api.py on exactly the lines marked `# error` (so the types are really read, not Any);
  3. stubtest finds the stub and the extension alike: no name missing from either, no property or method mismatched.
Exits 77 (ctest: skipped) with a message when mypy is not installed (Debian: apt-get install mypy)."""

import os
import pathlib
import re
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: check_typing.py BUILD_PYTHON_DIR (the directory holding the built package redres/)")
    package_root = pathlib.Path(sys.argv[1]).resolve()
    if not (package_root / "redres" / "_redres.pyi").is_file():
        sys.exit(f"check_typing.py: {package_root}/redres has no _redres.pyi: build the target redres_python first")
    try:
        import mypy.api  # noqa: F401  (only whether it is there)
    except ImportError:
        print("python.typing: SKIPPED: mypy is not installed (Debian's package `mypy`; scripts/install_deps.sh "
              "installs it)")
        sys.exit(77)

    env = dict(os.environ, MYPYPATH=str(package_root), PYTHONPATH=str(package_root))
    mypy = [sys.executable, "-m", "mypy", "--cache-dir=/dev/null", "--no-error-summary", "--show-error-codes",
            "--warn-unused-ignores", "--check-untyped-defs"]
    failures = []

    good = subprocess.run(mypy + [str(HERE / "uses_api.py"), str(package_root / "redres")], env=env,
                          capture_output=True, text=True, check=False)
    if good.returncode != 0:
        failures.append(f"mypy rejects uses_api.py or the package:\n{good.stdout}{good.stderr}")

    bad_file = HERE / "misuses_api.py"
    marked = {i for i, line in enumerate(bad_file.read_text().splitlines(), 1) if line.rstrip().endswith("# error")}
    bad = subprocess.run(mypy + [str(bad_file)], env=env, capture_output=True, text=True, check=False)
    reported = {int(m.group(1)) for m in re.finditer(r"^.*misuses_api\.py:(\d+): error:", bad.stdout, re.M)}
    if reported != marked:
        failures.append(f"mypy on misuses_api.py: errors on lines {sorted(reported)}, expected exactly "
                        f"{sorted(marked)}:\n{bad.stdout}{bad.stderr}")

    # pybind11's classes have their own metaclass, and those without a constructor an __init__(*args, **kwargs)
    # that raises: the stub says neither (so that mypy rejects Robot()). Every other difference fails.
    stubtest = subprocess.run([sys.executable, "-m", "mypy.stubtest", "redres._redres", "--concise"], env=env,
                              capture_output=True, text=True, check=False)
    expected = re.compile(r"^redres\._redres\.\w+ is inconsistent, metaclass differs$|"
                          r"^redres\._redres\.\w+\.__init__ is inconsistent, stub does not have \*args argument \"args\"$")
    differences = [line for line in stubtest.stdout.splitlines() if line.strip() and not expected.match(line)]
    if differences or (stubtest.returncode != 0 and not stubtest.stdout.strip()):
        failures.append("stubtest: the stub and the extension differ:\n" + "\n".join(differences) + stubtest.stderr)

    if failures:
        sys.exit("\n\n".join(failures))
    print("python.typing: mypy accepts uses_api.py and the package, rejects the", len(marked),
          "misuses, and stubtest matches the stub with the extension")


if __name__ == "__main__":
    main()
