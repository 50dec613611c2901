#!/usr/bin/env python3
"""The framework's areas and what each may include (docs/architecture.md), checked on the source tree.

Rules:
- every framework header and source lives in an area: framework/include/redres/<area>/ (public, installed) or
  framework/src/<area>/ (sources and private headers);
- a file of an area includes only its own area and the areas below it (ALLOWED);
- public headers include no private header, since an installed header could not find it;
- the framework (its areas, the CLI and the Python module) includes no plugin header, and the plugins include no
  private framework header: they are written as a plugin outside the project would be;
- every "redres/..." or private include names a file that exists.

Usage: check_layers.py [ROOT]   (exit 1 with one line per violation)
       check_layers.py --self-test   (checks that a tree with known violations is refused, and a clean one passes)
"""

import os
import re
import sys
import tempfile

# What each area may include besides itself. A DAG: lower areas never include higher ones.
ALLOWED = {
    "common": set(),
    "config": {"common"},
    "model": {"common", "config"},
    "parsers": {"common", "config", "model"},
    "qp": {"common", "config"},
    "control": {"common", "config", "model", "qp"},
    "run": {"common", "config", "model", "parsers", "qp", "control", "plant"},
    "extend": {"common", "config", "model", "parsers", "qp", "control", "run", "plant"},
    "plant": {"common", "config", "model"},
}
# The plugin kinds (their directories plugins/<plural>/ and plugins/include/redres/<plural>/) come from the one table
# of kinds, framework/src/extend/plugin_kinds.cpp: each kind is a line `kind("name", "plural", ...)` there.
KINDS_TABLE = "framework/src/extend/plugin_kinds.cpp"
KIND = re.compile(r'\bkind\(\s*"([^"]+)",\s*"([A-Za-z0-9_]+)"')

# Known breaks: (file, include) -> the reason and the change that removes it. A listed break that no longer occurs
# is reported, so that the list never outlives its reason.
EXCEPTIONS = {}

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def source_files(directory):
    for base, _, names in os.walk(directory):
        for name in sorted(names):
            if name.endswith((".hpp", ".cpp", ".h")):
                yield os.path.join(base, name)


def includes(path):
    with open(path, encoding="utf-8") as f:
        return INCLUDE.findall(f.read())


def plugin_dirs(root, problems):
    """The plural of every plugin kind in the table of kinds."""
    path = os.path.join(root, KINDS_TABLE)
    if not os.path.isfile(path):
        problems.append(f"{KINDS_TABLE}: missing (the table of plugin kinds)")
        return set()
    with open(path, encoding="utf-8") as f:
        kinds = {plural for _, plural in KIND.findall(f.read())}
    if not kinds:
        problems.append(f"{KINDS_TABLE}: no kind(\"name\", \"plural\", ...) line found")
    return kinds


def check(root):
    problems = []
    PLUGIN_DIRS = plugin_dirs(root, problems)
    used_exceptions = set()
    inc_root = os.path.join(root, "framework", "include", "redres")
    src_root = os.path.join(root, "framework", "src")
    plugin_inc = os.path.join(root, "plugins", "include")

    def rel(p):
        return os.path.relpath(p, root).replace(os.sep, "/")

    def target_of(name):
        """(area, public?, exists?) of an include the framework resolves, or None when it is not the framework's."""
        parts = name.split("/")
        if parts[0] == "redres" and len(parts) >= 3 and parts[1] in ALLOWED:
            return parts[1], True, os.path.isfile(os.path.join(inc_root, *parts[1:]))
        if parts[0] in ALLOWED and len(parts) >= 2:
            return parts[0], False, os.path.isfile(os.path.join(src_root, *parts))
        return None

    for flat in sorted(os.listdir(inc_root)):
        if os.path.isfile(os.path.join(inc_root, flat)):
            problems.append(f"framework/include/redres/{flat}: a header outside every area")
    for flat in sorted(os.listdir(src_root)):
        if os.path.isfile(os.path.join(src_root, flat)):
            problems.append(f"framework/src/{flat}: a source outside every area")

    for top, public in ((inc_root, True), (src_root, False)):
        for area in sorted(os.listdir(top)):
            if not os.path.isdir(os.path.join(top, area)):
                continue
            if area not in ALLOWED:
                problems.append(f"{rel(os.path.join(top, area))}: '{area}' is not an area (known: {', '.join(ALLOWED)})")
                continue
            for path in source_files(os.path.join(top, area)):
                for name in includes(path):
                    parts = name.split("/")
                    if parts[0] == "redres" and len(parts) >= 2 and parts[1] in PLUGIN_DIRS:
                        problems.append(f"{rel(path)}: includes the plugin header {name}")
                        continue
                    t = target_of(name)
                    if t is None:
                        continue
                    to_area, to_public, exists = t
                    if not exists:
                        problems.append(f"{rel(path)}: includes {name}, which does not exist")
                    if public and not to_public:
                        problems.append(f"{rel(path)}: a public header includes the private header {name}")
                    if (rel(path), name) in EXCEPTIONS:
                        used_exceptions.add((rel(path), name))
                    elif to_area != area and to_area not in ALLOWED[area]:
                        problems.append(f"{rel(path)}: area '{area}' includes {name} of area '{to_area}' "
                                        f"(allowed: {', '.join(sorted(ALLOWED[area])) or 'none'})")

    for app in ("framework/cli", "framework/python/src"):
        for path in source_files(os.path.join(root, app)):
            for name in includes(path):
                parts = name.split("/")
                if parts[0] == "redres" and len(parts) >= 2 and parts[1] in PLUGIN_DIRS:
                    problems.append(f"{rel(path)}: includes the plugin header {name}")

    for top in (os.path.join(root, "plugins"),):
        for path in source_files(top):
            for name in includes(path):
                t = target_of(name)
                if t is not None and not t[1]:
                    problems.append(f"{rel(path)}: a plugin includes the private framework header {name}")
    for (path, name), why in EXCEPTIONS.items():
        if (path, name) not in used_exceptions and os.path.isfile(os.path.join(root, path)):
            problems.append(f"{path}: listed exception for {name} no longer needed: remove it from EXCEPTIONS")
    if not os.path.isdir(plugin_inc):
        problems.append("plugins/include: missing")
    # Every directory of plugins is a kind of the table, so that the rules above cover it.
    for top in ("plugins", "plugins/include/redres"):
        full = os.path.join(root, top)
        if not os.path.isdir(full):
            continue
        for d in sorted(os.listdir(full)):
            if os.path.isdir(os.path.join(full, d)) and d != "include" and d not in PLUGIN_DIRS:
                problems.append(f"{top}/{d}: not a plugin kind of {KINDS_TABLE} (kinds: {', '.join(sorted(PLUGIN_DIRS))})")
    return problems


def write(root, path, text):
    full = os.path.join(root, path)
    os.makedirs(os.path.dirname(full), exist_ok=True)
    with open(full, "w", encoding="utf-8") as f:
        f.write(text)


def self_test():
    clean_tree = {
        KINDS_TABLE: 'k.push_back(kind("path", "paths", "the [path] table"));\n'
                     'k.push_back(kind("task", "tasks", "[[tasks]]"));\n'
                     'k.push_back(kind("engine", "engines", "[solver]"));\n',
        "framework/include/redres/common/error.hpp": "#pragma once\n",
        "framework/include/redres/model/robot.hpp": '#include "redres/common/error.hpp"\n',
        "framework/src/common/text.hpp": "#pragma once\n",
        "framework/src/model/robot.cpp": '#include "redres/model/robot.hpp"\n#include "common/text.hpp"\n',
        "plugins/include/redres/paths/line.hpp": '#include "redres/model/robot.hpp"\n',
        "framework/cli/main.cpp": '#include "redres/model/robot.hpp"\n',
    }
    planted = {
        "framework/include/redres/common/bad.hpp": '#include "redres/model/robot.hpp"\n',
        "framework/include/redres/model/leak.hpp": '#include "common/text.hpp"\n',
        "framework/src/model/plugin_user.cpp": '#include "redres/paths/line.hpp"\n#include "redres/qp/none.hpp"\n',
        "framework/include/redres/flat.hpp": "#pragma once\n",
        "plugins/paths/line.cpp": '#include "common/text.hpp"\n',
        "framework/cli/run.cpp": '#include "redres/engines/newton.hpp"\n',
        "framework/python/src/module.cpp": '#include "redres/tasks/frame_task.hpp"\n',
        "plugins/widgets/knob.cpp": '#include "redres/model/robot.hpp"\n',
    }
    with tempfile.TemporaryDirectory() as root:
        for path, text in clean_tree.items():
            write(root, path, text)
        clean = check(root)
        assert clean == [], clean
        for path, text in planted.items():
            write(root, path, text)
        found = check(root)
        wanted = [
            "area 'common' includes redres/model/robot.hpp of area 'model'",
            "a public header includes the private header common/text.hpp",
            "includes the plugin header redres/paths/line.hpp",
            "includes redres/qp/none.hpp, which does not exist",
            "area 'model' includes redres/qp/none.hpp of area 'qp'",
            "framework/include/redres/flat.hpp: a header outside every area",
            "a plugin includes the private framework header common/text.hpp",
            "framework/cli/run.cpp: includes the plugin header redres/engines/newton.hpp",
            "framework/python/src/module.cpp: includes the plugin header redres/tasks/frame_task.hpp",
            "plugins/widgets: not a plugin kind of framework/src/extend/plugin_kinds.cpp",
        ]
        for w in wanted:
            assert any(w in p for p in found), f"not reported: {w}\nreported: {found}"
        assert len(found) == len(wanted), found
        # Without the table of kinds, no plugin directory is known: that is reported, not passed.
        os.remove(os.path.join(root, KINDS_TABLE))
        assert any("the table of plugin kinds" in p for p in check(root)), check(root)
    print(f"check_layers self-test: {len(wanted)} planted violations reported, the clean tree passes")


def main(argv):
    if len(argv) > 1 and argv[1] == "--self-test":
        self_test()
        return 0
    root = argv[1] if len(argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
    problems = check(os.path.abspath(root))
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} layering violation(s); the areas and their rules: docs/architecture.md")
        return 1
    print(f"layers: every include of framework/ and plugins/ keeps to the areas ({len(EXCEPTIONS)} listed exceptions)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
