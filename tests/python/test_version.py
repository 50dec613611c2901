"""The version is written once, in the top-level CMakeLists.txt's project(VERSION): the CLI's --version, the Python
package's __version__ (from the extension) and the pip package's version (setup.py) all read it, and no other file
repeats it."""

import re
import subprocess
import sys

import redres
from conftest import ROOT, cli


def cmake_version():
    match = re.search(r"project\(\s*redres\s+VERSION\s+([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    assert match, "CMakeLists.txt has no project(redres VERSION ...)"
    return match.group(1)


def test_the_cli_the_module_and_cmake_agree_on_the_version():
    version = cmake_version()
    p = cli("--version")
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == f"redres {version}"
    assert redres.__version__ == version
    assert redres._redres.__version__ == version


def test_the_pip_package_reads_the_version_from_cmake():
    p = subprocess.run([sys.executable, "setup.py", "--version"], cwd=ROOT, capture_output=True, text=True,
                       check=False)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip().splitlines()[-1] == cmake_version()
    assert 'dynamic = ["version"]' in (ROOT / "pyproject.toml").read_text()


def test_no_other_source_writes_the_version():
    version = re.escape(cmake_version())
    for relative in ("framework/cli/main.cpp", "framework/python/redres/__init__.py", "framework/python/src/module.cpp",
                     "setup.py", "pyproject.toml"):
        text = (ROOT / relative).read_text()
        assert not re.search(rf"['\"]{version}['\"]|redres {version}", text), f"{relative} writes the version"
