#!/usr/bin/env python3
"""Puts the captures of scripts/console_captures.sh into docs/console.md:
    scripts/console_captures_into_docs.py OUT_DIR docs/console.md
Each `<!-- capture: NAME -->` line in the doc is followed by a fenced block; its content becomes
OUT_DIR/NAME.txt with the blank lines at its end left out. Every marker must have its capture
and every capture its marker, so that a screen added to one is not forgotten in the other."""
import pathlib
import re
import sys

out_dir, doc_path = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
doc = doc_path.read_text().split("\n")
captures = {p.stem: p.read_text().rstrip("\n").split("\n") for p in out_dir.glob("*.txt")}
used = set()
result = []
i = 0
while i < len(doc):
    result.append(doc[i])
    marker = re.fullmatch(r"<!-- capture: ([a-z0-9-]+) -->", doc[i])
    i += 1
    if not marker:
        continue
    name = marker.group(1)
    if name not in captures:
        sys.exit(f"{doc_path}: no capture {name}.txt in {out_dir}")
    if i >= len(doc) or doc[i] != "```":
        sys.exit(f"{doc_path}:{i + 1}: a fenced block must follow the marker of {name}")
    end = doc.index("```", i + 1)
    lines = captures[name]
    while lines and not lines[-1].strip():
        lines.pop()
    result += ["```"] + lines + ["```"]
    used.add(name)
    i = end + 1
missing = sorted(set(captures) - used)
if missing:
    sys.exit(f"{doc_path}: no marker for the captures {', '.join(missing)}")
doc_path.write_text("\n".join(result))
print(f"{doc_path}: {len(used)} captures from {out_dir}")
