#!/usr/bin/env python3
"""Independent reader for `c3po synth --format bop` output (used by
tests/cli/synth_bop.sh): parses the BOP JSON files with the standard library
and decodes the PNGs with zlib (no c3po code, no libspng), then checks the
BOP conventions and the consistency of depth, masks, poses and gt_info.

Usage: bop_check.py SPLIT_DIR IMAGES_PER_SCENE COUNT DIAMETER_MM BLEED
Prints one summary line; exits 1 with a message on the first failure."""
import json, os, struct, sys, zlib


def fail(message):
    print("bop_check: FAIL: " + message)
    sys.exit(1)


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(path + ": not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
    w, h, depth, colour, _, _, interlace = header
    if colour != 0 or interlace != 0:
        fail(path + ": expected a non-interlaced greyscale PNG")
    bpp = depth // 8
    stride = w * bpp
    raw = zlib.decompress(idat)
    rows, prev, i = [], bytearray(stride), 0
    for _ in range(h):
        f, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b = prev[x]
            c = prev[x - bpp] if x >= bpp else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    if bpp == 2:
        pixels = [[(r[2 * x] << 8) | r[2 * x + 1] for x in range(w)] for r in rows]
    else:
        pixels = [list(r) for r in rows]
    return w, h, depth, pixels


split, per_scene, count, diameter_mm, bleed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), int(sys.argv[5])
scenes = sorted(d for d in os.listdir(split) if os.path.isdir(os.path.join(split, d)))
expected = ["%06d" % s for s in range((count + per_scene - 1) // per_scene)]
if scenes != expected:
    fail("scene folders %s, expected %s" % (scenes, expected))
images = instances = 0
for s, scene in enumerate(scenes):
    folder = os.path.join(split, scene)
    camera = json.load(open(os.path.join(folder, "scene_camera.json")))
    gt = json.load(open(os.path.join(folder, "scene_gt.json")))
    info = json.load(open(os.path.join(folder, "scene_gt_info.json")))
    ids = sorted(int(k) for k in camera)
    if ids != list(range(min(per_scene, count - s * per_scene))):
        fail("%s: image ids %s" % (scene, ids))
    if sorted(camera) != sorted(gt) or sorted(gt) != sorted(info):
        fail(scene + ": the three JSON files disagree on the image ids")
    for im in ids:
        key = str(im)
        K, scale = camera[key]["cam_K"], camera[key]["depth_scale"]
        if len(K) != 9 or K[1] != 0 or K[3] != 0 or K[6:] != [0, 0, 1] or not scale > 0:
            fail("%s/%s: bad cam_K or depth_scale" % (scene, key))
        fx, cx, fy, cy = K[0], K[2], K[4], K[5]
        w, h, bits, depth = read_png(os.path.join(folder, "depth", "%06d.png" % im))
        if bits != 16:
            fail("depth PNG is %d-bit" % bits)
        if len(gt[key]) != len(info[key]) or not gt[key]:
            fail("%s/%s: scene_gt and scene_gt_info lists differ" % (scene, key))
        for g, (pose, meta) in enumerate(zip(gt[key], info[key])):
            R, t = pose["cam_R_m2c"], pose["cam_t_m2c"]
            if len(R) != 9 or len(t) != 3 or not isinstance(pose["obj_id"], int):
                fail("bad scene_gt entry")
            rows = [R[0:3], R[3:6], R[6:9]]   # row-major
            for a in range(3):
                for b in range(3):
                    dot = sum(rows[a][k] * rows[b][k] for k in range(3))
                    if abs(dot - (1 if a == b else 0)) > 1e-9:
                        fail("cam_R_m2c is not a rotation")
            name = "%06d_%06d.png" % (im, g)
            _, _, mbits, mask = read_png(os.path.join(folder, "mask", name))
            _, _, vbits, visib = read_png(os.path.join(folder, "mask_visib", name))
            if mbits != 8 or vbits != 8:
                fail("masks must be 8-bit")
            all_px = sum(1 for r in mask for m in r if m)
            vis_px = sum(1 for r in visib for m in r if m)
            valid = sum(1 for y in range(h) for x in range(w) if mask[y][x] and depth[y][x] > 0)
            if meta["px_count_all"] != all_px or meta["px_count_valid"] != valid:
                fail("%s/%s gt %d: px_count_all/valid disagree with the files" % (scene, key, g))
            if bleed == 0 and meta["px_count_visib"] != vis_px:
                fail("px_count_visib disagrees with mask_visib")
            if bleed > 0 and vis_px < meta["px_count_visib"]:
                fail("a bled mask_visib must contain the visible pixels")
            if g == 0:
                # The target's visible depth, back-projected, is centred near
                # cam_t_m2c (mm): within one diameter.
                pts = [((x - cx) * depth[y][x] * scale / fx, (y - cy) * depth[y][x] * scale / fy, depth[y][x] * scale)
                       for y in range(h) for x in range(w) if visib[y][x] and depth[y][x] > 0]
                if len(pts) < 100:
                    fail("target has %d measured pixels" % len(pts))
                for k in range(3):
                    values = sorted(p[k] for p in pts)
                    median = values[len(values) // 2]
                    if abs(median - t[k]) > diameter_mm:
                        fail("target depth pixels centred at %.1f mm on axis %d, cam_t_m2c says %.1f" % (median, k, t[k]))
            instances += 1
        images += 1
print("bop_check: %d images, %d instances in %d scene(s): OK" % (images, instances, len(scenes)))
