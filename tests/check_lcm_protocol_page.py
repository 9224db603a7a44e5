#!/usr/bin/env python3
"""docs/lcm-protocol.md must be enough to implement a rig: what it says of the bytes on the wire is
checked here against LCM's own Python code generator (`lcm-gen -p`) and Python's hmac, not against
bellows' codec (tests/test_lcm_codec.cpp checks bellows against the same page).

- every ```lcm block of the page is one of lcmtypes/*.lcm, character for character, and every type a
  rig speaks (RIG_TYPES) has its block;
- the fingerprint table gives each rig type's fingerprint as lcm-gen computes it;
- the worked examples (a signed command and a signed state, EXAMPLES below) are the bytes lcm-gen's
  encoder and HMAC-SHA256 give for the values and the key the page states.

usage: check_lcm_protocol_page.py ROOT            check ROOT/docs/lcm-protocol.md
       check_lcm_protocol_page.py ROOT --print    print the fingerprint table and the examples' dumps
       check_lcm_protocol_page.py ROOT --planted  check a copy of the page with one byte changed in a
                                                  dump: it must be reported (the check can fail)
"""
import hashlib
import hmac
import importlib
import pathlib
import re
import struct
import subprocess
import sys
import tempfile

RIG_TYPES = ("io_command_t", "io_state_t", "io_joints_command_t", "io_joints_state_t", "io_rig_limits_t")
EXAMPLE_KEY = bytes(range(32))  # the page's example key: the bytes 0x00, 0x01, ..., 0x1f
# The examples' values, as the page states them (field, value), in the order of the .lcm.
EXAMPLES = {
    "io_command_t": [("session_id", 1234567890123), ("seq", 1), ("utime", 0), ("rig_id", 987654321),
                     ("binding", 42), ("armed", True), ("inlet_duty", [0.25, 0.0]), ("outlet_duty", [0.0, 0.5])],
    "io_state_t": [("rig_id", 987654321), ("seq", 7), ("binding", 42), ("session_id", 1234567890123),
                   ("command_seq", 1), ("utime", 5000000), ("time_s", 5.0), ("angle_rad", 0.125),
                   ("chamber_bar", [1.5, 1.25]), ("supply_bar", 3.0), ("temperature_K", 293.15), ("fault_bits", 0),
                   ("foreign_commands", 0), ("unauthenticated_commands", 0)],
}
LCM_BLOCK = re.compile(r"^```lcm\n(.*?)^```", re.M | re.S)
STRUCT_NAME = re.compile(r"^struct (\w+)", re.M)
FINGERPRINT_ROW = re.compile(r"^\| `(\w+)` \| `([0-9a-f ]+)` \|", re.M)
DUMP_BLOCK = re.compile(r"^```text\n(# (\w+), signed with the example key\n.*?)^```", re.M | re.S)


def generated_types(root, directory):
    files = sorted(str(p) for p in (root / "lcmtypes").glob("*.lcm"))
    subprocess.run(["lcm-gen", "-p", "--ppath", directory] + files, check=True, stdout=subprocess.DEVNULL)
    sys.path.insert(0, directory)
    return {name: getattr(importlib.import_module("bellows." + name), name) for name in RIG_TYPES}


def signed_example(cls, name):
    message = cls()
    for field, value in EXAMPLES[name]:
        setattr(message, field, value)
    unsigned = message.encode()
    mac = hmac.new(EXAMPLE_KEY, unsigned[:-32], hashlib.sha256).digest()
    message.mac = list(struct.unpack(">32b", mac))
    return message.encode()


def dump(name, data, fields):
    """One line per field: its offset, its bytes (hex), what it is."""
    lines = ["# %s, signed with the example key" % name, "offset  bytes" + " " * 19 + "field"]
    rows = [("fingerprint", 8)]
    sizes = {int: 8, float: 8, bool: 1}
    for field, value in fields:
        if isinstance(value, list):
            rows += [("%s[%d] = %r" % (field, i, v), 8) for i, v in enumerate(value)]
        else:
            size = 4 if field == "fault_bits" else sizes[type(value)]
            rows.append(("%s = %s" % (field, str(value).lower() if isinstance(value, bool) else value), size))
    offset = 0
    for label, size in rows:
        lines.append("%6d  %-23s  %s" % (offset, " ".join("%02x" % b for b in data[offset:offset + size]), label))
        offset += size
    for start in range(offset, len(data), 8):
        lines.append("%6d  %-23s  %s" % (start, " ".join("%02x" % b for b in data[start:start + 8]),
                                         "mac[%d..%d]" % (start - offset, start - offset + 7)))
    return "\n".join(lines) + "\n"


def fingerprint_hex(cls):
    return " ".join("%02x" % b for b in cls._get_packed_fingerprint())


def check(root, page_text, types):
    problems = []
    files = {STRUCT_NAME.search(p.read_text()).group(1): p.read_text() for p in (root / "lcmtypes").glob("*.lcm")}
    shown = set()
    for block in LCM_BLOCK.findall(page_text):
        match = STRUCT_NAME.search(block)
        name = match.group(1) if match else "?"
        if files.get(name) != block:
            problems.append("the page's ```lcm block of %s is not lcmtypes/%s.lcm as it is" % (name, name))
        shown.add(name)
    problems += ["the page has no ```lcm block of %s, a type a rig speaks" % n for n in RIG_TYPES if n not in shown]
    rows = dict(FINGERPRINT_ROW.findall(page_text))
    for name in RIG_TYPES:
        if rows.get(name) != fingerprint_hex(types[name]):
            problems.append("the page gives %s's fingerprint as %s; lcm-gen computes %s" %
                            (name, rows.get(name), fingerprint_hex(types[name])))
    dumps = {name: text for text, name in DUMP_BLOCK.findall(page_text)}
    for name in EXAMPLES:
        expected = dump(name, signed_example(types[name], name), EXAMPLES[name])
        if name not in dumps:
            problems.append("the page has no dump of the example %s" % name)
        elif dumps[name] != expected:
            wrong = [i + 1 for i, (a, b) in enumerate(zip(dumps[name].splitlines(), expected.splitlines())) if a != b]
            problems.append("the page's dump of %s differs from lcm-gen's encoding and HMAC-SHA256 (lines %s)" %
                            (name, wrong or "count"))
    return problems


def main():
    root = pathlib.Path(sys.argv[1])
    mode = sys.argv[2] if len(sys.argv) > 2 else ""
    page = (root / "docs" / "lcm-protocol.md").read_text()
    with tempfile.TemporaryDirectory() as directory:
        types = generated_types(root, directory)
        if mode == "--print":
            print("| type | fingerprint (8 bytes, as on the wire) |\n|---|---|")
            for name in RIG_TYPES:
                print("| `%s` | `%s` |" % (name, fingerprint_hex(types[name])))
            for name in EXAMPLES:
                print("\n```text\n" + dump(name, signed_example(types[name], name), EXAMPLES[name]) + "```")
            return 0
        if mode == "--planted":
            start = page.index("# io_command_t, signed")
            line_start = page.index("session_id =", start)
            line_start = page.rindex("\n", 0, line_start) + 1
            line = page[line_start:page.index("\n", line_start)]
            planted = page[:line_start] + line.replace("01 1f", "01 1e", 1) + page[line_start + len(line):]
            problems = check(root, planted, types)
            print("\n".join(problems))
            return 0 if any("dump of io_command_t" in p for p in problems) else 1
        problems = check(root, page, types)
    for problem in problems:
        print("docs/lcm-protocol.md: " + problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
