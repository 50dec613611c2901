#!/usr/bin/env python3
"""The C++ blocks of the documentation, as translation units that the build compiles (tests/docs/CMakeLists.txt).

Every ```cpp block of README.md and docs/*.md carries a marker: an HTML comment on the line just before its fence
(Markdown viewers do not show it) that says how the block is compiled.

- <!-- snippet: file -->       a complete translation unit, compiled as it is;
- <!-- snippet: namespace -->  declarations (a Config, a class, a registration), compiled inside a namespace of its
                                own;
- <!-- snippet: body -->       statements, compiled as the body of a function with `const redres::RobotModel& robot`
                                in scope.

A namespace or body block gets a fixed prelude of framework headers (PRELUDE) unless it shows #include lines of its
own. Then those lines, moved to the top of the file, must be all it needs, so that the includes the docs show are
checked too. A block uses only what it defines or includes: a fragment that needs a Config or a class shows it.

Each generated file starts with `#line N "docs/file.md"`, and every line of it maps to a line of the Markdown file, so
that a compiler error points at the Markdown line. The blocks of a file are numbered from 1: the third block of
docs/writing_plugins.md is docs_writing_plugins_3.cpp, in the namespace redres_doc_snippet_docs_writing_plugins_3.

Refused, with file:line and exit code 1: a C++ block without a marker, a marker that is not on the line just before
a C++ block, an unknown kind, an unclosed fence, and an #include after the first line of code in a namespace or body
block.

Usage: extract_snippets.py ROOT --out DIR     writes DIR/<name>.cpp for every block (an unchanged file is not
                                              rewritten; a .cpp in DIR that no block makes is removed)
       extract_snippets.py ROOT --list        prints the names that --out writes, one a line, for CMake (no checks)
       extract_snippets.py ROOT --check [--compiled LIST]
                                              counts the ```cpp fences line by line and requires one generated
                                              translation unit per fence (and, with LIST, the files the build
                                              compiles, one a line, to be exactly those)
       extract_snippets.py --self-test        runs the generator on small Markdown files with known answers
"""

import os
import re
import subprocess
import sys
import tempfile

KINDS = ("file", "namespace", "body")

# The info strings that mark a C++ block.
CPP_LANGUAGES = {"cpp", "c++", "cxx", "cc", "hpp", "hxx", "h++"}

# What a namespace or body block sees when it shows no #include of its own: the framework's headers (not the
# plugins': a block that uses a built-in plugin's Config includes its header).
PRELUDE = [
    "<memory>",
    "<string>",
    "<vector>",
    "<Eigen/Core>",
    "<redres/config/config.hpp>",
    "<redres/config/toml_reader.hpp>",
    "<redres/model/robot.hpp>",
    "<redres/parsers/robot_toml.hpp>",
    "<redres/qp/lvi.hpp>",
    "<redres/control/plugin.hpp>",
    "<redres/control/path.hpp>",
    "<redres/control/engine_registry.hpp>",
]

FENCE = re.compile(r"^(?P<indent>[ \t]*)(?P<fence>`{3,}|~{3,})(?P<info>.*)$")
MARKER = re.compile(r"^\s*<!--\s*snippet:\s*(?P<kind>[A-Za-z_]+)\s*-->\s*$")
MARKER_LIKE = re.compile(r"^\s*<!--\s*snippet\b")
INCLUDE = re.compile(r"^\s*#\s*include\b")
# The independent count of --check: any line that opens a C++ fence, wherever it is.
CPP_FENCE_LINE = re.compile(r"^\s*(?:`{3,}|~{3,})\s*(?:" + "|".join(re.escape(x) for x in sorted(CPP_LANGUAGES)) +
                            r")(?:\s|\{|$)", re.I)


class Snippet:
    def __init__(self, page, ordinal, kind, marker_line, first_line, lines):
        self.page = page                # e.g. "docs/writing_plugins.md"
        self.ordinal = ordinal          # 1, 2, ... within the page
        self.kind = kind
        self.marker_line = marker_line  # 1-based line of the marker
        self.first_line = first_line    # 1-based line of the block's first line of code
        self.lines = lines              # the block's lines, indentation kept (so that columns match too)

    @property
    def stem(self):
        return re.sub(r"[^A-Za-z0-9]+", "_", os.path.splitext(self.page)[0]).strip("_") + f"_{self.ordinal}"

    @property
    def name(self):
        return self.stem + ".cpp"


def pages(root):
    """README.md and docs/*.md, as paths relative to root."""
    found = ["README.md"] if os.path.isfile(os.path.join(root, "README.md")) else []
    docs = os.path.join(root, "docs")
    if os.path.isdir(docs):
        found += [f"docs/{n}" for n in sorted(os.listdir(docs)) if n.endswith(".md")]
    return found


def cpp_language(info):
    words = info.strip().split()
    return bool(words) and words[0].lower() in CPP_LANGUAGES


def parse(page, text, errors):
    """Every C++ block of one page, in order; a block without a valid marker has kind None. Problems are appended
    to errors as "page:line: message"."""
    lines = text.split("\n")
    blocks = []
    marker = None  # (0-based line, kind) of a marker waiting for its block
    i = 0

    def refuse(index, message):
        errors.append(f"{page}:{index + 1}: {message}")

    def drop_marker():
        nonlocal marker
        if marker is not None:
            refuse(marker[0], "snippet marker not followed by a ```cpp block (it goes on the line just before the "
                              "fence)")
        marker = None

    while i < len(lines):
        line = lines[i]
        m = FENCE.match(line)
        if m and not (m["fence"][0] == "`" and "`" in m["info"]):
            fence = m["fence"]
            close = re.compile(r"^[ \t]*" + re.escape(fence[0]) + "{" + str(len(fence)) + r",}[ \t]*$")
            j = i + 1
            while j < len(lines) and not close.match(lines[j]):
                j += 1
            if j == len(lines):
                refuse(i, f"unclosed fence {fence}")
                break
            if cpp_language(m["info"]):
                kind, marker_line = None, 0
                if marker is None:
                    refuse(i, "a ```cpp block without a snippet marker: put <!-- snippet: file -->, "
                              "<!-- snippet: namespace --> or <!-- snippet: body --> on the line before the fence")
                else:
                    kind, marker_line = marker[1], marker[0] + 1
                marker = None
                blocks.append(Snippet(page, len(blocks) + 1, kind, marker_line, i + 2, lines[i + 1:j]))
            else:
                drop_marker()
            i = j + 1
            continue
        mk = MARKER.match(line)
        if mk:
            drop_marker()
            if mk["kind"] in KINDS:
                marker = (i, mk["kind"])
            else:
                refuse(i, f"unknown snippet kind '{mk['kind']}' (expected {', '.join(KINDS)})")
        elif MARKER_LIKE.match(line):
            drop_marker()
            refuse(i, "malformed snippet marker (expected <!-- snippet: KIND -->)")
        else:
            drop_marker()  # a marker belongs to the line just after it
        i += 1
    drop_marker()
    return blocks


def read_page(root, page):
    with open(os.path.join(root, page), encoding="utf-8") as f:
        return f.read()


def list_names(root):
    """--list: one name per C++ block, marked or not (the build's run of --out then refuses what is wrong)."""
    return [b.name for page in pages(root) for b in parse(page, read_page(root, page), [])]


def quoted(page):
    return '"' + page.replace("\\", "\\\\").replace('"', '\\"') + '"'


def translation_unit(s, errors):
    """The text of the generated file for snippet s."""
    where = quoted(s.page)
    note = (f"// Generated by tests/docs/extract_snippets.py from this `{s.kind}` block of {s.page}; do not edit.")
    if s.kind == "file":
        return f"#line {s.marker_line} {where}\n{note}\n#line {s.first_line} {where}\n" + "\n".join(s.lines) + "\n"
    # Leading #include lines go to the top of the file; the block keeps an empty line in their place.
    includes, code, in_head = [], [], True
    for k, line in enumerate(s.lines):
        if INCLUDE.match(line):
            if not in_head:
                errors.append(f"{s.page}:{s.first_line + k}: #include after code in a `{s.kind}` block: "
                              "move it to the top of the block")
            includes.append((s.first_line + k, line.strip()))
            code.append("")
        else:
            if line.strip() and not line.strip().startswith("//"):
                in_head = False
            code.append(line)
    out = [f"#line {s.marker_line} {where}", note]
    if includes:
        for number, line in includes:
            out += [f"#line {number} {where}", line]
    else:
        for header in PRELUDE:
            out += [f"#line {s.marker_line} {where}", f"#include {header}"]
    namespace = f"redres_doc_snippet_{s.stem}"
    out.append(f"#line {s.marker_line} {where}")
    if s.kind == "namespace":
        out.append(f"namespace {namespace} {{")
    else:
        out.append(f"namespace redres {{ class RobotModel; }}  namespace {namespace} {{ "
                   "void snippet([[maybe_unused]] const redres::RobotModel& robot) {")
    out.append(f"#line {s.first_line} {where}")
    out += code
    out.append("}" if s.kind == "namespace" else "} }")
    return "\n".join(out) + "\n"


def extract(root):
    """(snippets with their generated text, errors)."""
    errors, result = [], []
    for page in pages(root):
        for s in parse(page, read_page(root, page), errors):
            if s.kind is not None:
                result.append((s, translation_unit(s, errors)))
    return result, errors


def write_all(root, out_dir):
    """Writes the translation units; returns (names written, errors). Writes nothing when there are errors."""
    result, errors = extract(root)
    if errors:
        return [], errors
    os.makedirs(out_dir, exist_ok=True)
    names = []
    for s, text in result:
        path = os.path.join(out_dir, s.name)
        names.append(s.name)
        old = None
        if os.path.isfile(path):
            with open(path, encoding="utf-8") as f:
                old = f.read()
        if old != text:  # unchanged files keep their time stamp, so that they are not compiled again
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
    for n in os.listdir(out_dir):
        if n.endswith(".cpp") and n not in names:
            os.remove(os.path.join(out_dir, n))
    return names, []


def check(root, compiled_list):
    """--check: the count of ```cpp fences, line by line, against the translation units made from them."""
    problems = []
    fences = 0
    for page in pages(root):
        fences += sum(1 for line in read_page(root, page).split("\n") if CPP_FENCE_LINE.match(line))
    with tempfile.TemporaryDirectory() as out:
        _, errors = write_all(root, out)
        made = sorted(n for n in os.listdir(out) if n.endswith(".cpp")) if not errors else []
    problems += errors
    if not errors and len(made) != fences:
        problems.append(f"{fences} ```cpp blocks in the docs, {len(made)} generated from them: every block must be "
                        "one the generator reads (is one inside another fence?)")
    if compiled_list is not None and not errors:
        with open(compiled_list, encoding="utf-8") as f:
            compiled = sorted(os.path.basename(x.strip()) for x in f if x.strip().endswith(".cpp"))
        if compiled != made:
            missing = sorted(set(made) - set(compiled))
            extra = sorted(set(compiled) - set(made))
            problems.append(f"the build compiles {len(compiled)} snippets, the docs have {len(made)}"
                            f" (not compiled: {', '.join(missing) or 'none'}; no longer in the docs: "
                            f"{', '.join(extra) or 'none'}): re-run cmake")
    return problems, fences


def run_self(args):
    return subprocess.run([sys.executable, os.path.abspath(__file__)] + args, capture_output=True, text=True)


def self_test():
    failures = []

    def expect(condition, what):
        if not condition:
            failures.append(what)

    def tree(root, files):
        for path, text in files.items():
            full = os.path.join(root, path)
            os.makedirs(os.path.dirname(full), exist_ok=True)
            with open(full, "w", encoding="utf-8") as f:
                f.write(text)

    refused = {
        "unmarked": ("Text.\n\n```cpp\nint x = 1;\n```\n", "docs/a.md:3: a ```cpp block without a snippet marker"),
        "marker not just before": ("<!-- snippet: body -->\n\n```cpp\nint x = 1;\n```\n",
                                   "docs/a.md:1: snippet marker not followed"),
        "marker before toml": ("<!-- snippet: body -->\n```toml\nx = 1\n```\n", "docs/a.md:1: snippet marker not"),
        "unknown kind": ("<!-- snippet: statements -->\n```cpp\nint x = 1;\n```\n",
                         "docs/a.md:1: unknown snippet kind 'statements'"),
        "malformed marker": ("<!-- snippet body -->\n```cpp\nint x = 1;\n```\n", "docs/a.md:1: malformed snippet"),
        "late include": ("<!-- snippet: body -->\n```cpp\nint x = 1;\n#include <vector>\n```\n",
                         "docs/a.md:4: #include after code"),
        "unclosed fence": ("<!-- snippet: file -->\n```cpp\nint x = 1;\n", "docs/a.md:2: unclosed fence"),
        "unmarked c++ in a list": ("- item:\n\n  ```c++\n  int x = 1;\n  ```\n", "docs/a.md:3: a ```cpp block"),
    }
    for case, (text, message) in refused.items():
        with tempfile.TemporaryDirectory() as root:
            tree(root, {"README.md": "# Title\n", "docs/a.md": text})
            r = run_self([root, "--out", os.path.join(root, "out")])
            expect(r.returncode == 1, f"{case}: exit code {r.returncode}, expected 1")
            expect(message in r.stderr, f"{case}: expected '{message}' in: {r.stderr.strip()}")
            expect(not os.path.isdir(os.path.join(root, "out")), f"{case}: files were written")
            c = run_self([root, "--check"])
            expect(c.returncode == 1, f"{case}: --check passed")

    good = {
        "README.md": "# T\n\n<!-- snippet: body -->\n```cpp\nint n = robot.dof();\n```\n",
        "docs/b.md": ("Intro.\n<!-- snippet: file -->\n```cpp\nint main() { return 0; }\n```\n\n"
                      "- A list item:\n\n  <!-- snippet: namespace -->\n  ```cpp\n  #include <vector>\n\n"
                      "  std::vector<int> v;\n  ```\n\n```toml\nx = 1\n```\n"),
    }
    with tempfile.TemporaryDirectory() as root:
        tree(root, good)
        out = os.path.join(root, "out")
        r = run_self([root, "--out", out])
        expect(r.returncode == 0, f"clean tree refused: {r.stderr.strip()}")
        made = sorted(os.listdir(out)) if os.path.isdir(out) else []
        expect(made == ["README_1.cpp", "docs_b_1.cpp", "docs_b_2.cpp"], f"generated {made}")
        listed = run_self([root, "--list"]).stdout.split()
        expect(listed == ["README_1.cpp", "docs_b_1.cpp", "docs_b_2.cpp"], f"--list gave {listed}")
        if len(made) == 3:
            with open(os.path.join(out, "README_1.cpp"), encoding="utf-8") as f:
                body = f.read()
            expect(body.startswith('#line 3 "README.md"\n'), "body: does not start with the marker's #line")
            expect("const redres::RobotModel& robot" in body, "body: no robot in scope")
            expect("#include <redres/model/robot.hpp>" in body, "body: no prelude")
            expect('#line 5 "README.md"\nint n = robot.dof();\n' in body, "body: code not at its Markdown line")
            with open(os.path.join(out, "docs_b_1.cpp"), encoding="utf-8") as f:
                whole = f.read()
            expect('#line 4 "docs/b.md"\nint main() { return 0; }\n' in whole, "file: not compiled as it is")
            expect("namespace" not in whole, "file: wrapped")
            with open(os.path.join(out, "docs_b_2.cpp"), encoding="utf-8") as f:
                ns = f.read()
            expect('#line 11 "docs/b.md"\n#include <vector>\n' in ns, "namespace: own include not hoisted")
            expect("<redres/control/plugin.hpp>" not in ns, "namespace: prelude added beside its own includes")
            expect("namespace redres_doc_snippet_docs_b_2 {" in ns, "namespace: not wrapped")
            expect('#line 11 "docs/b.md"\n\n\n  std::vector<int> v;\n}' in ns, "namespace: code lines moved")
        tree(root, {"docs/stale.md": ""})
        with open(os.path.join(out, "old_1.cpp"), "w", encoding="utf-8") as f:
            f.write("")
        run_self([root, "--out", out])
        expect(not os.path.exists(os.path.join(out, "old_1.cpp")), "a stale file was kept")
        c = run_self([root, "--check"])
        expect(c.returncode == 0, f"--check refused the clean tree: {c.stderr.strip()}")
        listing = os.path.join(root, "compiled.txt")
        with open(listing, "w", encoding="utf-8") as f:
            f.write(os.path.join(out, "README_1.cpp") + "\n" + os.path.join(out, "docs_b_1.cpp") + "\n")
        c = run_self([root, "--check", "--compiled", listing])
        expect(c.returncode == 1 and "not compiled: docs_b_2.cpp" in c.stderr,
               f"--check accepted a build that leaves a block out: {c.stderr.strip()}")
        # A ```cpp fence that the generator does not take as a block (here: inside a ````markdown block) is still
        # counted, so that --check fails rather than leave it unchecked.
        tree(root, {"docs/c.md": "````markdown\n```cpp\nint y;\n```\n````\n"})
        c = run_self([root, "--check"])
        expect(c.returncode == 1 and "4 ```cpp blocks in the docs, 3 generated" in c.stderr,
               f"--check missed a block the generator skips: {c.stderr.strip()}")

    if failures:
        for f in failures:
            print(f"extract_snippets self-test: {f}", file=sys.stderr)
        return 1
    print(f"extract_snippets self-test: {len(refused)} broken pages refused, a clean one generated and checked")
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    root, mode, rest = argv[1], argv[2], argv[3:]
    if mode == "--list" and not rest:
        print("\n".join(list_names(root)))
        return 0
    if mode == "--out" and len(rest) == 1:
        names, errors = write_all(root, rest[0])
        for e in errors:
            print(e, file=sys.stderr)
        return 1 if errors else 0
    if mode == "--check" and (not rest or (len(rest) == 2 and rest[0] == "--compiled")):
        problems, fences = check(root, rest[1] if rest else None)
        for p in problems:
            print(p, file=sys.stderr)
        if problems:
            return 1
        print(f"docs snippets: {fences} ```cpp blocks, each generated as a translation unit"
              + (" and compiled by the build" if rest else ""))
        return 0
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
