// A minimal c3po detector plugin: "centroid" places the object's keypoints
// (model frame) so that their centroid lands on the centroid of the cloud,
// without rotating them. A real detector (a network, a feature matcher)
// fills in Detect the same way; C-3PO's corrector and certificates then
// decide whether the resulting pose can be trusted.
//
// Written only against the C header c3po/plugins/plugin_api.h (stable ABI):
// the plugin links no c3po code, and c3po refuses it at load time if it was
// built for another C3PO_PLUGIN_ABI_VERSION.
#include <c3po/plugins/plugin_api.h>

#include <new>
#include <vector>

// c3po's own tests build this file three times (tests/targets/test_plugin):
// as it is, registered under another name, and with a wrong ABI version.
#ifndef CENTROID_PLUGIN_NAME
#define CENTROID_PLUGIN_NAME "centroid"
#endif
#ifndef CENTROID_PLUGIN_ABI
#define CENTROID_PLUGIN_ABI C3PO_PLUGIN_ABI_VERSION
#endif

namespace {

struct CentroidDetector {
  std::vector<double> centred_keypoints;   // b_i - mean(b), point-major x0 y0 z0 x1 ...
};

// Per thread, since c3po may call detect from several threads at once.
thread_local const char* last_error = "";

void* Create(const double* model_keypoints, int num_keypoints, double /*diameter*/, const char* /*model_path*/) {
  if (model_keypoints == nullptr || num_keypoints <= 0) return nullptr;   // c3po reports the failure
  auto* detector = new (std::nothrow) CentroidDetector;
  if (detector == nullptr) return nullptr;
  double mean[3] = {0.0, 0.0, 0.0};
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
    last_error = "empty cloud";
    return 1;
  }
  const auto* detector = static_cast<const CentroidDetector*>(instance);
  double centroid[3] = {0.0, 0.0, 0.0};
  for (int i = 0; i < num_points; ++i) {
    for (int a = 0; a < 3; ++a) centroid[a] += cloud[3 * i + a] / num_points;
  }
  for (std::size_t k = 0; k < detector->centred_keypoints.size(); ++k) {
    keypoints_out[k] = detector->centred_keypoints[k] + centroid[k % 3];
  }
  return 0;
}

const char* LastError(void* /*instance*/) { return last_error; }

const c3po_detector_plugin kPlugin = {
    CENTROID_PLUGIN_ABI,   // checked by c3po when it loads the plugin
    CENTROID_PLUGIN_NAME,
    "example plugin: the model keypoints moved onto the cloud centroid (no rotation)",
    Create, Destroy, Detect, LastError};

}  // namespace

extern "C" __attribute__((visibility("default"))) const c3po_detector_plugin* c3po_detector_plugin_v1(void) {
  return &kPlugin;
}
