#!/usr/bin/env python3
"""The engine's layers stay layers: every file of engine/<layer>/ includes only its own layer, the
layers its CMake target links (directly or through another layer), and no project code outside
engine/; nothing in the engine includes ncurses, LCM, sockets, files or parsers; every source of a
layer folder is built by its target. The layers and their links are read from engine/CMakeLists.txt
(its bellows_engine_layer calls), so that file stays the one description.

usage: check_engine_layers.py ROOT            check the tree at ROOT
       check_engine_layers.py ROOT --planted  check a copy with one planted violation per rule: each
                                              must be reported (the check can fail)
"""
import pathlib
import re
import shutil
import sys
import tempfile

FORBIDDEN_SYSTEM = ("ncurses", "curses.h", "lcm/", "sys/socket.h", "netinet/", "fstream", "filesystem",
                    "toml++", "nlohmann/", "matio", "modbus")
OUTSIDE = ("app/", "ui/", "sessions/", "bridge/", "devices/", "lcmtypes/")


def layers_of(root):
    """{layer: (sources, links)} from engine/CMakeLists.txt's bellows_engine_layer(...) calls."""
    text = (root / "engine" / "CMakeLists.txt").read_text()
    text = re.sub(r"#[^\n]*", "", text)
    layers = {}
    for name, body in re.findall(r"bellows_engine_layer\(\s*(\w+)(.*?)\)", text, re.S):
        words = body.split()
        sources, links, into = [], [], None
        for word in words:
            if word in ("SOURCES", "LINKS"):
                into = sources if word == "SOURCES" else links
            elif into is not None:
                into.append(word)
        layers[name] = (sources, [l[len("bellows_engine_"):] for l in links if l.startswith("bellows_engine_")])
    return layers


def reachable(layers, layer):
    seen, todo = set(), list(layers[layer][1])
    while todo:
        below = todo.pop()
        if below not in seen:
            seen.add(below)
            todo.extend(layers.get(below, ((), ()))[1])
    return seen


def check(root):
    layers = layers_of(root)
    problems = []
    if not layers:
        return ["engine/CMakeLists.txt declares no layers"]
    for path in sorted((root / "engine").iterdir()):
        if path.is_file() and path.name != "CMakeLists.txt":
            problems.append(f"engine/{path.name}: outside every layer folder")
        elif path.is_dir() and path.name not in layers:
            problems.append(f"engine/{path.name}/: a folder no bellows_engine_layer declares")
    for layer, (sources, _) in layers.items():
        allowed = reachable(layers, layer) | {layer}
        folder = root / "engine" / layer
        for cpp in sorted(folder.glob("*.cpp")):
            if cpp.name not in sources:
                problems.append(f"engine/{layer}/{cpp.name}: not among the layer's SOURCES (never built)")
        for path in sorted(list(folder.glob("*.hpp")) + list(folder.glob("*.cpp"))):
            for number, line in enumerate(path.read_text().splitlines(), 1):
                where = f"engine/{layer}/{path.name}:{number}"
                own = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
                system = re.match(r"\s*#\s*include\s+<([^>]+)>", line)
                if own:
                    target = own.group(1)
                    used = re.match(r"engine/(\w+)/", target)
                    if used and used.group(1) not in allowed:
                        problems.append(f"{where}: layer '{layer}' includes {target} of layer '{used.group(1)}', "
                                        f"which it does not link (allowed: {', '.join(sorted(allowed))})")
                    elif target.startswith(OUTSIDE):
                        problems.append(f"{where}: the engine includes {target} from outside engine/")
                    elif target.startswith("engine/") and not used:
                        problems.append(f"{where}: {target} names no layer folder")
                elif system and any(bad in system.group(1) for bad in FORBIDDEN_SYSTEM):
                    problems.append(f"{where}: the engine includes <{system.group(1)}> (no terminal, files, "
                                    "parsers, LCM or sockets here)")
    return problems


def planted(root):
    """Every rule must catch its planted violation, and only the planted one."""
    layers = layers_of(root)
    low = next(name for name in layers if not layers[name][1] or name == "base")
    high = next(name for name in reversed(list(layers)) if name != low)
    high_header = sorted((root / "engine" / high).glob("*.hpp"))[0].name
    plants = {
        "includes a higher layer": (low, f'#include "engine/{high}/{high_header}"'),
        "includes outside": (low, '#include "ui/canvas.hpp"'),
        "includes a forbidden system header": (low, "#include <ncurses.h>"),
    }
    failures = []
    for rule, (layer, line) in plants.items():
        with tempfile.TemporaryDirectory() as tmp:
            copy = pathlib.Path(tmp)
            shutil.copytree(root / "engine", copy / "engine")
            (copy / "engine" / layer / "planted_violation.hpp").write_text(line + "\n")
            found = check(copy)
            if len(found) != 1 or "planted_violation" not in found[0]:
                failures.append(f"planted violation '{rule}' reported as {found}")
    with tempfile.TemporaryDirectory() as tmp:
        copy = pathlib.Path(tmp)
        shutil.copytree(root / "engine", copy / "engine")
        (copy / "engine" / low / "unlisted_source.cpp").write_text("\n")
        (copy / "engine" / "stray.hpp").write_text("\n")
        found = check(copy)
        if len(found) != 2:
            failures.append(f"unlisted source and stray file reported as {found}")
    return failures


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
    problems = planted(root) if "--planted" in sys.argv[2:] else check(root)
    for problem in problems:
        print(problem, file=sys.stderr)
    if not problems:
        print(f"engine layers: {', '.join(layers_of(root))}: every include within its links")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
