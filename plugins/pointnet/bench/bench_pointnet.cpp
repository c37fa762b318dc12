// c3po_bench_pointnet: prints the pointnet network's training and inference
// throughput on random clouds. Usage: c3po_bench_pointnet [seconds] [num_points] [batch]
// Threads: C3PO_THREADS (default: all cores).
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "c3po/plugins/pointnet.hpp"

int main(int argc, char** argv) {
  c3po::PointNetBenchmarkOptions options;
  if (argc > 1) options.seconds = std::atof(argv[1]);
  if (argc > 2) options.num_points = std::atoi(argv[2]);
  if (argc > 3) options.batch = std::atoi(argv[3]);
  try {
    const c3po::PointNetBenchmarkResult r = c3po::RunPointNetBenchmark(options);
    std::printf("pointnet: n = %d points, batch %d, %d keypoints, %zu parameters, %d threads\n",
                options.num_points, options.batch, options.num_keypoints, r.parameters, r.threads);
    std::printf("training : %8.1f samples/s  (%8.1f per CPU-second)\n", r.train_samples_per_second,
                r.train_samples_per_cpu_second);
    std::printf("inference: %8.1f clouds/s   (%8.1f per CPU-second, batches of %d)\n",
                r.inference_clouds_per_second, r.inference_clouds_per_cpu_second,
                options.inference_batch);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "c3po_bench_pointnet: %s\n", e.what());
    return 2;
  }
  return 0;
}
