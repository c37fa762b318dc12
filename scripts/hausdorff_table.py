#!/usr/bin/env python3
"""Judge `c3po certify --bop ... --json` lines against the BOP ground truth.

Usage: hausdorff_table.py MODEL.obj LABEL=FILE.jsonl [LABEL=FILE.jsonl ...]
       [--correct 0.02] [--stride 16]

MODEL.obj: the object's mesh in metres (e.g. ycbv-bop/models_m/*.obj). A pose
is correct when the Hausdorff distance between the mesh vertices (every
--stride-th) posed at gt_R/gt_t and at R/t is at most --correct (metres). For
every file prints one Markdown row: instances, % certified, % certified and
correct, false certificates (certified and not correct), % correct. Lines with
an "error" count as not certified and not correct. Measurement only (standard
library; no c3po code): docs/method.md "Self-training on real frames".
"""
import json
import math
import sys


def read_vertices(path, stride):
    vertices = []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                vertices.append(tuple(float(x) for x in line.split()[1:4]))
    return vertices[::stride]


def pose(rows, t, points):
    return [tuple(sum(rows[r][c] * p[c] for c in range(3)) + t[r] for r in range(3)) for p in points]


def directed(a, b, bound):
    # max over a of min over b, with the early break of Taha & Hanbury (2015).
    worst = 0.0
    for p in a:
        best = math.inf
        for q in b:
            d = (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2 + (p[2] - q[2]) ** 2
            if d < best:
                best = d
                if best <= worst:
                    break
        worst = max(worst, best)
        if worst > bound:
            return math.sqrt(worst)
    return math.sqrt(worst)


def main(argv):
    correct = 0.02
    stride = 16
    args = []
    i = 1
    while i < len(argv):
        if argv[i] == "--correct":
            correct = float(argv[i + 1]); i += 2
        elif argv[i] == "--stride":
            stride = int(argv[i + 1]); i += 2
        else:
            args.append(argv[i]); i += 1
    if len(args) < 2:
        sys.exit(__doc__)
    model = read_vertices(args[0], stride)
    print("| method | n | % certified | % certified and correct | false certificates | % correct |")
    print("|---|---|---|---|---|---|")
    for spec in args[1:]:
        label, path = spec.split("=", 1)
        n = certified = good = false = correct_count = 0
        with open(path) as f:
            for line in f:
                if not line.strip():
                    continue
                j = json.loads(line)
                n += 1
                if "error" in j or j.get("R") is None:
                    continue
                truth = pose(j["gt_R"], j["gt_t"], model)
                estimate = pose(j["R"], j["t"], model)
                # Above the threshold the exact value does not matter.
                h = max(directed(truth, estimate, correct), directed(estimate, truth, correct))
                ok = h <= correct
                correct_count += ok
                if j["certified"]:
                    certified += 1
                    good += ok
                    false += not ok
        pct = lambda k: 100.0 * k / n if n else float("nan")
        print(f"| {label} | {n} | {pct(certified):.1f} | {pct(good):.1f} | {false} | {pct(correct_count):.1f} |")


if __name__ == "__main__":
    main(sys.argv)
