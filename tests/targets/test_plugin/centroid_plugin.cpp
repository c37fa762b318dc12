// A tiny detector plugin for tests/unit/plugin_test.cpp, written only against
// the C entry point of c3po/plugins/plugin_api.h (no c3po library code).
// "centroid": the model keypoints translated so that their centroid lands on
// the centroid of the cloud (no rotation). Compile-time switches build the
// variants the loader test needs: another registry name, a wrong ABI version.
#include <cstring>
#include <vector>

#include "c3po/plugins/plugin_api.h"

#ifndef C3PO_TEST_PLUGIN_NAME
#define C3PO_TEST_PLUGIN_NAME "centroid"
#endif
#ifndef C3PO_TEST_PLUGIN_ABI
#define C3PO_TEST_PLUGIN_ABI C3PO_PLUGIN_ABI_VERSION
#endif

namespace {

struct CentroidDetector {
  std::vector<double> centred_keypoints;   // b_i - mean(b), point-major
};

// Per thread: detect may run on several threads at once.
thread_local const char* last_error_message = "";

void* Create(const double* model_keypoints, int num_keypoints, double /*diameter*/,
             const char* /*model_path*/) {
  if (!model_keypoints || num_keypoints <= 0) return nullptr;
  auto* detector = new CentroidDetector;
  double mean[3] = {0, 0, 0};
  for (int i = 0; i < num_keypoints; ++i) {
    for (int a = 0; a < 3; ++a) mean[a] += model_keypoints[3 * i + a] / num_keypoints;
  }
  detector->centred_keypoints.resize(3 * static_cast<std::size_t>(num_keypoints));
  for (int i = 0; i < num_keypoints; ++i) {
    for (int a = 0; a < 3; ++a) detector->centred_keypoints[3 * i + a] = model_keypoints[3 * i + a] - mean[a];
  }
  return detector;
}

void Destroy(void* instance) { delete static_cast<CentroidDetector*>(instance); }

int Detect(void* instance, const double* cloud, int num_points, double* keypoints_out) {
  if (num_points <= 0) {
    last_error_message = "empty cloud";
    return 1;
  }
  const auto* detector = static_cast<const CentroidDetector*>(instance);
  double centroid[3] = {0, 0, 0};
  for (int i = 0; i < num_points; ++i) {
    for (int a = 0; a < 3; ++a) centroid[a] += cloud[3 * i + a] / num_points;
  }
  const std::size_t count = detector->centred_keypoints.size() / 3;
  for (std::size_t i = 0; i < count; ++i) {
    for (int a = 0; a < 3; ++a) keypoints_out[3 * i + a] = detector->centred_keypoints[3 * i + a] + centroid[a];
  }
  return 0;
}

const char* LastError(void*) { return last_error_message; }

const c3po_detector_plugin kTable = {
    C3PO_TEST_PLUGIN_ABI, C3PO_TEST_PLUGIN_NAME,
    "test plugin: model keypoints moved onto the cloud centroid",
    Create, Destroy, Detect, LastError};

}  // namespace

extern "C" const c3po_detector_plugin* c3po_detector_plugin_v1(void) { return &kTable; }
