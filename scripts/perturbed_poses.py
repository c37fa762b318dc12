#!/usr/bin/env python3
"""Perturbed ground-truth poses of a BOP split as BOP results CSVs: wrong poses
to provoke the certificates with (`c3po certify --poses`).

Usage: perturbed_poses.py SPLIT_DIR OUT_DIR [--count 20] [--seed 7]

SPLIT_DIR holds scene folders with scene_gt.json (e.g.
../shared/data/real/ycbv-bop/test). Writes OUT_DIR/p0.csv .. p{count-1}.csv:
file k has one row per ground-truth instance, the pose turned by
ANGLES[k % 10] degrees about a random axis through the model origin and
shifted by a random one of SHIFTS_MM in a random direction (R_gt·Rot, t_gt +
shift). Certify each file with and without --no-correct; every certificate
for a pose whose Hausdorff distance to the truth exceeds 2 cm is false
(gt_hausdorff in the lines; independently: hausdorff_table.py). Measurement
only (standard library; no c3po code): docs/method.md "Provocation on real
frames".
"""
import json
import math
import os
import random
import sys

ANGLES = [5, 10, 20, 30, 45, 60, 90, 120, 150, 180]   # degrees
SHIFTS_MM = [0, 10, 20, 40]


def rotation(axis, angle):
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    C = 1 - c
    return [[c + x * x * C, x * y * C - z * s, x * z * C + y * s],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C]]


def product(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def unit(rng):
    while True:
        v = [rng.gauss(0, 1) for _ in range(3)]
        n = math.sqrt(sum(a * a for a in v))
        if n > 1e-6:
            return [a / n for a in v]


def main(argv):
    args, options = [], {}
    i = 0
    while i < len(argv):
        if argv[i].startswith("--") and i + 1 < len(argv):
            options[argv[i]] = argv[i + 1]
            i += 2
        else:
            args.append(argv[i])
            i += 1
    if len(args) != 2 or set(options) - {"--count", "--seed"}:
        sys.exit(__doc__)
    split, out = args[0], args[1]
    count = int(options.get("--count", 20))
    rng = random.Random(int(options.get("--seed", 7)))
    os.makedirs(out, exist_ok=True)
    files = [open(os.path.join(out, "p%d.csv" % k), "w") for k in range(count)]
    for f in files:
        f.write("scene_id,im_id,obj_id,score,R,t,time\n")
    scenes = sorted(d for d in os.listdir(split) if os.path.isfile(os.path.join(split, d, "scene_gt.json")))
    for scene in scenes:
        gt = json.load(open(os.path.join(split, scene, "scene_gt.json")))
        for im in sorted(gt, key=int):
            for instance in gt[im]:
                R = [instance["cam_R_m2c"][3 * i:3 * i + 3] for i in range(3)]
                t = instance["cam_t_m2c"]
                for k, f in enumerate(files):
                    shift = rng.choice(SHIFTS_MM)
                    turned = product(R, rotation(unit(rng), math.radians(ANGLES[k % len(ANGLES)])))
                    direction = unit(rng)
                    moved = [t[i] + shift * direction[i] for i in range(3)]
                    f.write("%d,%s,%d,1,%s,%s,-1\n" % (
                        int(scene), im, instance["obj_id"],
                        " ".join("%.9f" % turned[i][j] for i in range(3) for j in range(3)),
                        " ".join("%.4f" % a for a in moved)))
    for f in files:
        f.close()


if __name__ == "__main__":
    main(sys.argv[1:])
