"""Checks that scipy reads every field of a bellows MAT export with the right values.

Usage: check_mat_scipy.py FILE.mat EXPECTED.json
EXPECTED.json mirrors the MAT file's variables (objects: structs, arrays of objects: struct
arrays, arrays of strings: cell arrays, arrays of numbers: column vectors). Exits 1 naming the
first field that differs, 0 when all agree (numbers exactly, NaN as NaN).
"""
import json
import math
import sys

import numpy as np
from scipy.io import loadmat


def fail(path, why):
    print(f"{path}: {why}")
    sys.exit(1)


def as_list(got):
    """A struct array or cell array as a list (loadmat squeezes a 1 x 1 one to its element)."""
    if isinstance(got, np.ndarray) and got.dtype == object:
        return list(got.ravel())
    if isinstance(got, (list, tuple)):
        return list(got)
    return [got]


def same_number(a, b):
    return (math.isnan(a) and math.isnan(b)) or a == b


def compare(got, want, path):
    if isinstance(want, dict):
        if not isinstance(got, dict):
            fail(path, f"expected a struct, found {type(got).__name__}")
        if set(got) != set(want):
            fail(path, f"fields {sorted(got)} differ from {sorted(want)}")
        for key in want:
            compare(got[key], want[key], f"{path}.{key}")
    elif isinstance(want, list) and want and all(isinstance(w, dict) for w in want):
        items = as_list(got)
        if len(items) != len(want):
            fail(path, f"{len(items)} structs, expected {len(want)}")
        for i, (g, w) in enumerate(zip(items, want)):
            compare(g, w, f"{path}({i + 1})")
    elif isinstance(want, list) and want and all(isinstance(w, str) for w in want):
        items = [str(g) for g in as_list(got)] if not isinstance(got, str) else [got]
        if items != want:
            fail(path, f"names {items[:5]}... differ from {want[:5]}...")
    elif isinstance(want, str):
        if want == "" and np.asarray(got).size == 0:
            return  # an empty MATLAB char array reads as an empty array
        if not isinstance(got, str) or got != want:
            fail(path, f"text {got!r} differs from {want!r}")
    else:
        values = np.atleast_1d(np.asarray(got, dtype=float)).ravel()
        expected = np.atleast_1d(np.asarray(want, dtype=float)).ravel()
        if values.shape != expected.shape:
            fail(path, f"{values.size} numbers, expected {expected.size}")
        for i, (a, b) in enumerate(zip(values, expected)):
            if not same_number(a, b):
                fail(f"{path}[{i}]", f"{a!r} differs from {b!r}")


def main():
    mat = loadmat(sys.argv[1], simplify_cells=True)
    with open(sys.argv[2]) as f:
        expected = json.load(f)
    for name, want in expected.items():
        if name not in mat:
            fail(name, "variable missing")
        compare(mat[name], want, name)
    print(f"scipy read {len(expected)} variables; every field agrees")


main()
