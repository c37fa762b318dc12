#!/usr/bin/python3
"""The reference C-3PO keypoint corrector (plain gradient descent), in PyTorch,
rerun on the very cases of `c3po bench corrector`, to compare speeds.

Not part of c3po (c3po never calls Python); a measuring stick for issue 4's
"gd is >= 10x faster than the reference PyTorch implementation on CPU".

What it implements, the way the authors' PyTorch code computes it
(method.md, "Correct"):
  * y = y_detected + correction, correction = 0 at the start;
  * T(y) = (R, t) by the SVD registration of the model keypoints b onto y:
    M = Y_c B_c^T, M = U S V^T, R = U diag(1, 1, det U det V) V^T,
    t = mean(y) - R mean(b), differentiated by autograd through the SVD;
  * the whole model sample B^ is posed, R B^ + t, at every evaluation, and the
    nearest posed model point of every input point is found by dense pairwise
    squared distances (in chunks, without autograd); the loss is then
    recomputed on the selected pairs with autograd, which gives the same
    value and gradient as the reference's K=1 nearest-neighbour search;
  * f = kappa * L_pc + theta * L_kp with L_pc the mean (or max) squared
    distance and L_kp = (1/N) sum_i ||y_i - T b_i||^2 (c3po's definition;
    the reference's MSELoss divides by 3N instead: pass --reference-kp-scale
    to use that);
  * gradient by torch.autograd.functional.jacobian of the batched objective,
    correction -= lr * gradient on the samples still moving, stop when every
    |f_k - f_{k+1}| < tol or after max_iterations (lr 0.1, 1000, 1e-12 by
    default; read from the cases file).

How to run (one thread each, same clouds, same perturbed keypoints):
  c3po bench corrector OBJ.json --data DEPTH_DIR --sigma 0.3 --solvers gd \
      --threads 1 --max-clouds 10 --cases /tmp/cases.jsonl
  /usr/bin/python3 libc3po/eval/bench/pytorch_corrector_gd.py /tmp/cases.jsonl \
      --max-cases 10 [--dtype float64] [--batch 1] [--max-iterations 30] [--json out.json]
It prints, per cloud, the iterations and milliseconds of both
implementations and their final objective values, then the medians and the
speed ratios per cloud and per iteration. In float32 (the reference's type)
|f_k - f_{k+1}| rarely drops below 1e-12, so the loop runs all 1000
iterations, about 3 minutes per cloud on one core: --max-iterations gives the
time per iteration in seconds. Needs torch and numpy (not c3po dependencies).
"""
import argparse
import json
import statistics
import sys
import time

import numpy as np
import torch


def read_ply_xyz(path):
    """x, y, z of a PLY file (ascii or binary little endian, float/double)."""
    with open(path, "rb") as stream:
        header = []
        while True:
            line = stream.readline()
            if not line:
                raise ValueError(f"{path}: truncated PLY header")
            line = line.decode("ascii", "replace").strip()
            header.append(line)
            if line == "end_header":
                break
        fmt, count, props, in_vertex = None, 0, [], False
        for line in header:
            words = line.split()
            if words[:1] == ["format"]:
                fmt = words[1]
            elif words[:2] == ["element", "vertex"]:
                count, in_vertex = int(words[2]), True
            elif words[:1] == ["element"]:
                in_vertex = False
            elif words[:1] == ["property"] and in_vertex:
                props.append((words[2], words[1]))
        types = {"float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8",
                 "uchar": "u1", "uint8": "u1", "int": "<i4", "int32": "<i4"}
        if fmt == "binary_little_endian":
            dtype = np.dtype([(name, types[kind]) for name, kind in props])
            data = np.frombuffer(stream.read(count * dtype.itemsize), dtype=dtype, count=count)
            return np.stack([data["x"], data["y"], data["z"]]).astype(np.float64)
        if fmt == "ascii":
            rows = np.loadtxt(stream, max_rows=count, ndmin=2)
            names = [name for name, _ in props]
            return rows[:, [names.index("x"), names.index("y"), names.index("z")]].T.astype(np.float64)
        raise ValueError(f"{path}: unsupported PLY format {fmt}")


def register(model_keypoints, keypoints):
    """SVD registration (eq. 8) of b (1, 3, N) onto y (B, 3, N): R (B,3,3), t (B,3,1)."""
    b_mean = model_keypoints.mean(dim=2, keepdim=True)
    y_mean = keypoints.mean(dim=2, keepdim=True)
    m = (keypoints - y_mean) @ (model_keypoints - b_mean).transpose(1, 2)
    u, _, vh = torch.linalg.svd(m)
    d = torch.ones(keypoints.shape[0], 3, dtype=keypoints.dtype)
    d[:, 2] = torch.linalg.det(u) * torch.linalg.det(vh)
    rotation = u @ torch.diag_embed(d) @ vh
    return rotation, y_mean - rotation @ b_mean


def nearest_indices(cloud, posed_model, chunk=256):
    """Index of the nearest column of posed_model (B,3,m) for every column of cloud (B,3,n)."""
    with torch.no_grad():
        model_sq = (posed_model * posed_model).sum(dim=1)  # (B, m)
        out = []
        for start in range(0, cloud.shape[2], chunk):
            x = cloud[:, :, start:start + chunk]
            sq = (x * x).sum(dim=1).unsqueeze(2) + model_sq.unsqueeze(1) - 2.0 * x.transpose(1, 2) @ posed_model
            out.append(sq.argmin(dim=2))
        return torch.cat(out, dim=1)  # (B, n)


class Objective:
    """f(correction) for a batch: kappa L_pc(T(y)) + theta L_kp(y)."""

    def __init__(self, model_sample, model_keypoints, clouds, detected, kappa, theta, loss, kp_scale):
        self.model_sample, self.model_keypoints = model_sample, model_keypoints
        self.clouds, self.detected = clouds, detected
        self.kappa, self.theta, self.loss, self.kp_scale = kappa, theta, loss, kp_scale

    def __call__(self, correction):
        y = self.detected + correction
        rotation, translation = register(self.model_keypoints, y)
        posed_model = rotation @ self.model_sample + translation            # (B, 3, m)
        index = nearest_indices(self.clouds, posed_model)                   # (B, n)
        matched = torch.gather(posed_model, 2, index.unsqueeze(1).expand(-1, 3, -1))
        squared = ((self.clouds - matched) ** 2).sum(dim=1)                 # (B, n)
        point_cloud = squared.mean(dim=1) if self.loss == "mean" else squared.max(dim=1).values
        residual = y - (rotation @ self.model_keypoints + translation)
        keypoint = (residual ** 2).sum(dim=(1, 2)) / (residual.shape[2] * self.kp_scale)
        return (self.kappa * point_cloud + self.theta * keypoint).unsqueeze(1)  # (B, 1)


def gradient_descent(objective, detected, lr, max_iterations, tol):
    """The reference's batched loop; returns correction, iterations per sample, f per sample."""
    batch = detected.shape[0]
    correction = torch.zeros_like(detected)
    iterations = torch.zeros(batch, dtype=torch.long)
    f_next = objective(correction)
    moving = torch.ones(batch, dtype=torch.bool)
    step = 0
    while step < max_iterations:
        step += 1
        f_now = f_next
        jacobian = torch.autograd.functional.jacobian(objective, correction)  # (B, 1, B, 3, N)
        rows = torch.arange(batch)
        gradient = jacobian[rows, 0, rows]
        correction = correction - lr * gradient * moving.view(-1, 1, 1).to(detected.dtype)
        iterations += moving.long()
        f_next = objective(correction)
        change = (f_now - f_next).abs().squeeze(1)
        if change.max() < tol:
            break
        moving = change > tol
    return correction, iterations, f_next.squeeze(1)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("cases", help="JSON lines from `c3po bench corrector --cases FILE`")
    parser.add_argument("--method", default="corrector (gd)", help="which c3po rows to rerun and compare")
    parser.add_argument("--sigma", type=float, default=None, help="only cases of this sigma")
    parser.add_argument("--max-cases", type=int, default=10)
    parser.add_argument("--batch", type=int, default=1, help="clouds per batch (reference: whole batches)")
    parser.add_argument("--dtype", choices=["float32", "float64"], default="float32",
                        help="float32 like the reference; float64 like c3po")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--reference-kp-scale", action="store_true",
                        help="L_kp as the reference's MSELoss (divide by 3N, not N)")
    parser.add_argument("--max-iterations", type=int, default=None,
                        help="cap the iterations (cheaper runs: compare ms per iteration)")
    parser.add_argument("--json", help="write the per-case results here")
    args = parser.parse_args()
    torch.set_num_threads(args.threads)
    dtype = torch.float32 if args.dtype == "float32" else torch.float64

    with open(args.cases) as stream:
        header = json.loads(stream.readline())
        cases = [json.loads(line) for line in stream if line.strip()]
    cases = [c for c in cases if c["method"] == args.method and (args.sigma is None or c["sigma"] == args.sigma)]
    cases = cases[:args.max_cases]
    if not cases:
        sys.exit(f"{args.cases}: no case with method '{args.method}'")
    options = header["corrector"]
    model_sample = torch.tensor(header["model_sample"], dtype=dtype).T.unsqueeze(0)
    model_keypoints = torch.tensor(header["model_keypoints"], dtype=dtype).T.unsqueeze(0)
    print(f"{header['object']}: model sample {model_sample.shape[2]} points, "
          f"{model_keypoints.shape[2]} keypoints, loss {options['loss']}, kappa {options['kappa']}, "
          f"theta {options['theta']}, lr {options['gd_step']}, <= {options['gd_max_iterations']} iterations, "
          f"tol {options['gd_tolerance']}, {args.dtype}, batch {args.batch}, {torch.get_num_threads()} thread(s)")
    print(f"{'sigma':>6} {'cloud':>5} {'iters torch':>11} {'iters c3po':>10} {'ms torch':>10} {'ms c3po':>9} "
          f"{'f torch':>11} {'f c3po':>11}")
    results = []
    for first in range(0, len(cases), args.batch):
        group = cases[first:first + args.batch]
        clouds = [read_ply_xyz(header["clouds"][c["cloud"]]) for c in group]
        if len({cloud.shape[1] for cloud in clouds}) != 1:
            sys.exit("clouds of one batch must have equal sizes (use --batch 1)")
        cloud = torch.tensor(np.stack(clouds), dtype=dtype)
        detected = torch.tensor([c["detected_keypoints"] for c in group], dtype=dtype).transpose(1, 2)
        objective = Objective(model_sample, model_keypoints, cloud, detected, options["kappa"],
                              options["theta"], options["loss"], 3.0 if args.reference_kp_scale else 1.0)
        start, cpu_start = time.perf_counter(), time.process_time()
        max_iterations = options["gd_max_iterations"]
        if args.max_iterations is not None:
            max_iterations = min(max_iterations, args.max_iterations)
        _, iterations, final = gradient_descent(objective, detected, options["gd_step"],
                                                max_iterations, options["gd_tolerance"])
        ms = 1e3 * (time.perf_counter() - start) / len(group)
        cpu_ms = 1e3 * (time.process_time() - cpu_start) / len(group)
        for k, case in enumerate(group):
            row = {"sigma": case["sigma"], "cloud": case["cloud"], "torch_iterations": int(iterations[k]),
                   "c3po_iterations": case["iterations"], "torch_ms": ms, "torch_cpu_ms": cpu_ms,
                   "c3po_ms": case["corrector_ms"], "c3po_cpu_ms": case["corrector_cpu_ms"],
                   "torch_f": float(final[k]), "c3po_f": case["cost_after"]}
            results.append(row)
            print(f"{row['sigma']:6.2f} {row['cloud']:5d} {row['torch_iterations']:11d} {row['c3po_iterations']:10d} "
                  f"{row['torch_ms']:10.1f} {row['c3po_ms']:9.2f} {row['torch_f']:11.4e} {row['c3po_f']:11.4e}",
                  flush=True)
    median = lambda key: statistics.median(r[key] for r in results)
    torch_per_iteration = median("torch_ms") / max(median("torch_iterations"), 1)
    c3po_per_iteration = median("c3po_ms") / max(median("c3po_iterations"), 1)
    print(f"median over {len(results)} clouds: torch {median('torch_ms'):.1f} ms "
          f"({median('torch_iterations'):.0f} iterations, {torch_per_iteration:.3f} ms/iteration), "
          f"c3po gd {median('c3po_ms'):.2f} ms ({median('c3po_iterations'):.0f} iterations, "
          f"{c3po_per_iteration:.3f} ms/iteration)")
    print(f"c3po gd is {torch_per_iteration / max(c3po_per_iteration, 1e-9):.0f}x faster per iteration")
    if args.max_iterations is None:
        print(f"c3po gd is {median('torch_ms') / max(median('c3po_ms'), 1e-9):.0f}x faster per cloud")
    else:
        # Capped: a cloud would take the iterations the uncapped loop needs
        # (at least c3po's count, in float32 usually all of them).
        print(f"capped at {args.max_iterations} iterations: per cloud, torch would need >= "
              f"{torch_per_iteration * median('c3po_iterations'):.0f} ms for c3po's "
              f"{median('c3po_iterations'):.0f} iterations "
              f"({torch_per_iteration * median('c3po_iterations') / max(median('c3po_ms'), 1e-9):.0f}x c3po)")
    if args.json:
        with open(args.json, "w") as stream:
            json.dump(results, stream, indent=1)


if __name__ == "__main__":
    main()
