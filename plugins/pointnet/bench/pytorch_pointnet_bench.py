#!/usr/bin/env python3
"""The same PointNet keypoint regressor in PyTorch, for a side-by-side speed
comparison with c3po_bench_pointnet (not a c3po dependency).

Network: shared per-point MLP 3 -> 64 -> 128 -> 256 (1x1 convolutions, ReLU),
max over points, fully connected 256 -> 256 -> 128 -> 3N (ReLU between);
Adam, mean squared keypoint error; random clouds of n points.

Setup on Debian: apt-get install python3-torch libopenblas0-pthread
(with the default reference BLAS PyTorch is an order of magnitude slower).

Usage: /usr/bin/python3 pytorch_pointnet_bench.py [seconds] [num_points] [batch]
Threads: C3PO_THREADS (default: all cores), like c3po_bench_pointnet.
"""
import os
import sys
import time

import torch
from torch import nn


def make_network(num_keypoints):
    encoder = nn.Sequential(
        nn.Conv1d(3, 64, 1), nn.ReLU(),
        nn.Conv1d(64, 128, 1), nn.ReLU(),
        nn.Conv1d(128, 256, 1), nn.ReLU())
    head = nn.Sequential(
        nn.Linear(256, 256), nn.ReLU(),
        nn.Linear(256, 128), nn.ReLU(),
        nn.Linear(128, 3 * num_keypoints))

    class PointNet(nn.Module):
        def __init__(self):
            super().__init__()
            self.encoder = encoder
            self.head = head

        def forward(self, points):                      # (B, 3, n)
            features = self.encoder(points)              # (B, 256, n)
            pooled = features.max(dim=2).values          # (B, 256)
            return self.head(pooled)                     # (B, 3N)

    return PointNet()


def rate(seconds, items, step):
    step()  # warm-up
    start = time.perf_counter()
    cpu_start = time.process_time()
    done = 0
    while True:
        step()
        done += items
        elapsed = time.perf_counter() - start
        if elapsed >= seconds:
            return done / elapsed, done / (time.process_time() - cpu_start)


def main():
    seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 3.0
    num_points = int(sys.argv[2]) if len(sys.argv) > 2 else 512
    batch = int(sys.argv[3]) if len(sys.argv) > 3 else 32
    num_keypoints, inference_batch = 10, 64
    torch.set_num_threads(int(os.environ.get("C3PO_THREADS", os.cpu_count())))
    torch.manual_seed(0)
    net = make_network(num_keypoints)
    optimizer = torch.optim.Adam(net.parameters(), lr=1e-3)
    clouds = torch.rand(batch, 3, num_points) - 0.5
    targets = torch.rand(batch, 3 * num_keypoints) - 0.5
    test = torch.rand(inference_batch, 3, num_points) - 0.5

    def train_step():
        optimizer.zero_grad()
        out = net(clouds)
        loss = ((out - targets) ** 2).sum(dim=1).mean() / num_keypoints
        loss.backward()
        optimizer.step()

    def inference_step():
        with torch.no_grad():
            net(test)

    train, train_cpu = rate(seconds, batch, train_step)
    infer, infer_cpu = rate(seconds, inference_batch, inference_step)
    print(f"pytorch {torch.__version__}: n = {num_points} points, batch {batch}, "
          f"{num_keypoints} keypoints, {torch.get_num_threads()} threads, "
          f"{sum(p.numel() for p in net.parameters())} parameters")
    print(f"training : {train:8.1f} samples/s  ({train_cpu:8.1f} per CPU-second)")
    print(f"inference: {infer:8.1f} clouds/s   ({infer_cpu:8.1f} per CPU-second, batches of {inference_batch})")


if __name__ == "__main__":
    main()
