// certify_cloud: loads an object, reads a point cloud, estimates the object's
// pose with a built-in detector and prints the C-3PO certificate.
//
//   certify_cloud OBJECT.json CLOUD.(ply|pcd|xyz) [DETECTOR]   (default: svd)
//
// Exit status: 0 certified, 1 not certified, 2 bad input.
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include "c3po/base/version.hpp"
#include "c3po/io/cloud_io.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/object/object_io.hpp"
#include "c3po/plugins/registry.hpp"

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: %s OBJECT.json CLOUD [DETECTOR]   (c3po %s)\n", argv[0], C3PO_VERSION);
    return 2;
  }
  try {
    const c3po::ObjectModel object = c3po::LoadObject(argv[1]);
    const c3po::PointSet cloud = c3po::ReadCloud(argv[2]);
    const std::unique_ptr<c3po::Detector> detector =
        c3po::CreateDetector(argc == 4 ? argv[3] : "svd", object);

    // The thresholds eps_oc and delta_nd stored in the object file.
    c3po::PipelineOptions options;
    options.certificate = c3po::CertificateOptions::FromObject(object.spec());
    const c3po::PoseEstimate estimate =
        c3po::EstimateAndCertify(object, cloud, detector->Detect(cloud), options);
    if (!estimate.ok()) {
      std::printf("%s: not certified (registration failed)\n", argv[2]);
      return 1;
    }
    const c3po::Certificate& certificate = estimate.certificate;
    const c3po::Pose& pose = estimate.scene_from_model;
    std::printf("%s: %s\n", argv[2], estimate.certified() ? "CERTIFIED" : "not certified");
    std::printf("  observable correctness: %s (max point distance %.6g, eps_oc %.6g)\n",
                certificate.oc.passed ? "yes" : "no", certificate.oc.max_point_distance, certificate.oc.eps_oc);
    std::printf("  non-degeneracy:         %s (indicator set %d, delta_nd %.6g)\n",
                certificate.nd.passed ? "yes" : "no", certificate.nd.passing_set, certificate.nd.delta_nd);
    if (certificate.nd.local_checked) {
      std::printf("    local test:           %s (smallest generalised eigenvalue %.3g)\n",
                  certificate.nd.local.passed ? "yes" : "no", certificate.nd.local.min_eigenvalue);
    }
    if (certificate.nd.global_checked) {
      std::printf("    no far rival:         %s (%d of %d turned starts fit as well)\n",
                  certificate.nd.global.passed ? "yes" : "no", certificate.nd.global.rivals_found,
                  certificate.nd.global.rivals_tried);
    }
    std::printf("  scene_from_model t = [%.5f %.5f %.5f]\n", pose.t(0), pose.t(1), pose.t(2));
    for (int row = 0; row < 3; ++row) {
      std::printf("  %s [%.5f %.5f %.5f]\n", row == 0 ? "R =" : "   ", pose.R(row, 0), pose.R(row, 1),
                  pose.R(row, 2));
    }
    return estimate.certified() ? 0 : 1;
  } catch (const std::exception& error) {   // c3po::InputError: "file: problem"
    std::fprintf(stderr, "certify_cloud: %s\n", error.what());
    return 2;
  }
}
