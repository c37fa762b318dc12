// c3po bench pointnet: training and inference speed of the PointNet detector
// on random data. Registered by bench_entries.cpp as {SetupPointNetBench}.
#include <cstdio>
#include <functional>
#include <memory>

#include "c3po/base/error.hpp"
#include "c3po/plugins/pointnet.hpp"
#include "command.hpp"

namespace c3po::cli {

void SetupPointNetBench(CLI::App& parent, std::function<int()>* run) {
  auto options = std::make_shared<PointNetBenchmarkOptions>();
  CLI::App* sub = parent.add_subcommand("pointnet", "PointNet training and inference speed (random data)");
  sub->add_option("--points", options->num_points, "Points per cloud (n)");
  sub->add_option("--batch", options->batch, "Training batch size");
  sub->add_option("--keypoints", options->num_keypoints, "Keypoints (N)");
  sub->add_option("--inference-batch", options->inference_batch, "Inference batch size");
  sub->add_option("--seconds", options->seconds, "Seconds per measurement");
  sub->add_option("--threads", options->threads, "Threads (0 = all cores)");
  sub->footer("Example:\n  c3po bench pointnet --points 512 --batch 32");
  sub->callback([options, run]() {
    *run = [options]() {
      try {
        options->Check();
      } catch (const std::invalid_argument& e) {
        throw InputError("pointnet", e.what());
      }
      const PointNetBenchmarkResult r = RunPointNetBenchmark(*options);
      std::printf("pointnet (%zu parameters), n = %d, N = %d, %d thread(s):\n", r.parameters, options->num_points,
                  options->num_keypoints, r.threads);
      std::printf("  training : %8.1f samples/s (batch %d)   %8.1f samples per CPU-second\n",
                  r.train_samples_per_second, options->batch, r.train_samples_per_cpu_second);
      std::printf("  inference: %8.1f clouds/s  (batch %d)   %8.1f clouds per CPU-second\n",
                  r.inference_clouds_per_second, options->inference_batch, r.inference_clouds_per_cpu_second);
      return 0;
    };
  });
}

}  // namespace c3po::cli
