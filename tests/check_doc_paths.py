#!/usr/bin/env python3
"""A map that names files must name files that exist: every path a document mentions under one of the
project's folders exists (a glob matches something; `engine/control/control_core` is its .hpp or
.cpp), and every code name it quotes in backticks (`EngineCore::tick()`, `TrialRecord::joints[j]`,
`kMustBeArmed`) is a word of the product's sources (or a ctest name), so a renamed file or function shows here.

usage: check_doc_paths.py ROOT DOC...          check DOCs (paths relative to ROOT)
       check_doc_paths.py ROOT DOC --planted   check a copy of DOC with a missing path and a missing
                                               name added: both must be reported (the check can fail)
"""
import glob
import pathlib
import re
import sys
import tempfile

FOLDERS = ("app", "ui", "sessions", "bridge", "devices", "engine", "lcmtypes", "tests", "bench", "docs", "scripts",
           "cmake")
PRODUCT = ("app", "ui", "sessions", "bridge", "devices", "engine")
PATH = re.compile(r"(?<![\w./-])((?:%s)/[\w./*-]*[\w*/])" % "|".join(FOLDERS))
CODE_SPAN = re.compile(r"`([^`\n]+)`")
IDENTIFIER = re.compile(r"[A-Za-z_]\w*")
# A quoted span that is code: a qualified name or a call, or one identifier spelled like a type or a
# constant (CamelCase, kConstant) or with an inner underscore (a function or key name).
CODE_LIKE = re.compile(r"^[A-Za-z_][\w:]*(\([^)]*\))?(\[[^\]]*\])?(\.[A-Za-z_][\w:]*(\([^)]*\))?)*$")


def path_exists(root, path):
    path = path.rstrip("/.")
    if any(c in path for c in "*?["):
        return bool(glob.glob(str(root / path)))
    target = root / path
    if target.exists():
        return True
    return target.suffix == "" and any(target.with_suffix(s).exists() for s in (".hpp", ".cpp"))


def source_words(root):
    words = set()
    for folder in PRODUCT:
        for file in (root / folder).rglob("*"):
            if file.suffix in (".hpp", ".cpp", ".in", ".txt"):
                words.update(IDENTIFIER.findall(file.read_text(errors="replace")))
    for registrations in (root / "tests").rglob("CMakeLists.txt"):  # ctest names
        words.update(IDENTIFIER.findall(registrations.read_text(errors="replace")))
    return words


def is_code(span):
    if not CODE_LIKE.match(span):
        return False
    if "::" in span or "(" in span or "[" in span:
        return True
    return bool(re.search(r"[A-Z]", span)) or bool(re.match(r"^[a-z]+_\w*[a-z]$", span))


def problems_in(root, doc, words, counts=None):
    found = []
    counts = counts if counts is not None else {"paths": 0, "names": 0}
    for number, line in enumerate(doc.read_text().splitlines(), 1):
        for path in PATH.findall(line):
            counts["paths"] += 1
            if not path_exists(root, path):
                found.append(f"{doc}:{number}: no such file or folder: {path}")
        for span in CODE_SPAN.findall(line):
            span = span.strip()
            if not is_code(span):
                continue
            # The names, not the arguments: `Trajectory::joint(j)` checks Trajectory and joint.
            names = IDENTIFIER.findall(re.sub(r"\([^)]*\)|\[[^\]]*\]", "", span))
            counts["names"] += len(names)
            missing = [n for n in names if n not in words]
            if missing:
                found.append(f"{doc}:{number}: `{span}`: not in the product's sources: {', '.join(missing)}")
    return found


def main(argv):
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    root = pathlib.Path(argv[1]).resolve()
    planted = "--planted" in argv[2:]
    docs = [root / d for d in argv[2:] if d != "--planted"]
    words = source_words(root)
    if planted:
        with tempfile.TemporaryDirectory() as temp:
            copy = pathlib.Path(temp) / docs[0].name
            copy.write_text(docs[0].read_text() + "\nSee `engine/rt/no_such_file.hpp` and `EngineCore::no_such_call()`.\n")
            found = problems_in(root, copy, words)
        wanted = ("engine/rt/no_such_file.hpp", "no_such_call")
        caught = [w for w in wanted if any(w in p for p in found)]
        if len(caught) != len(wanted) or len(found) != len(wanted):
            print("the check missed a planted problem or reported another one:", *found, sep="\n  ", file=sys.stderr)
            return 1
        print(f"caught both planted problems in a copy of {docs[0].name}")
        return 0
    counts = {"paths": 0, "names": 0}
    found = [p for doc in docs for p in problems_in(root, doc, words, counts)]
    for problem in found:
        print(problem, file=sys.stderr)
    if not found:
        print(f"{counts['paths']} paths and {counts['names']} code names in {', '.join(d.name for d in docs)}: all exist")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
