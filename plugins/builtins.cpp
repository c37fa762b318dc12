// The detectors compiled into c3po: one registration per built-in detector.
#include "registry_internal.hpp"

#ifdef C3PO_HAVE_SVD
#include "c3po/plugins/svd_detector.hpp"
#endif
#ifdef C3PO_HAVE_FPFH
#include "c3po/plugins/fpfh_detector.hpp"
#endif
#ifdef C3PO_HAVE_POINTNET
#include "c3po/plugins/pointnet.hpp"
#endif

namespace c3po {

void RegisterBuiltinDetectors() {
#ifdef C3PO_HAVE_SVD
  // "pca": principal-axes (PCA) rotation hypotheses refined by ICP. "svd" is
  // the same detector under its first name (scripts use --detector svd).
  for (const char* name : {"pca", "svd"}) {
    RegisterDetector({name, std::string(name) == "pca"
                                ? "PCA rotation hypotheses refined by ICP (no training); alias: svd"
                                : "the pca detector (its first name)",
                      false},
                     [](const ObjectModel& object) -> std::unique_ptr<Detector> {
                       return std::make_unique<SvdDetector>(object);
                     });
  }
#endif
#ifdef C3PO_HAVE_FPFH
  RegisterDetector({"fpfh", "FPFH matching + TEASER-style robust registration (no training)", false},
                   [](const ObjectModel& object) -> std::unique_ptr<Detector> {
                     return std::make_unique<FpfhDetector>(object);
                   });
#endif
#ifdef C3PO_HAVE_POINTNET
  RegisterModelLoader({"pointnet", "PointNet keypoint regressor (tiny-dnn); train with c3po train", true},
                      [](const std::string& path, const ObjectModel& object) -> std::unique_ptr<Detector> {
                        return PointNetDetector::Load(path, object);
                      });
#endif
}

}  // namespace c3po
