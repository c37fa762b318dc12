// Identity among known objects (identity_check.hpp).
#include "c3po/method/identity_check.hpp"

#include <exception>
#include <optional>
#include <stdexcept>

#include "c3po/base/error.hpp"
#include "c3po/base/interrupt.hpp"

namespace c3po {

void KnownObject::Check() const {
  if (object == nullptr || detector == nullptr) {
    throw std::invalid_argument("KnownObject '" + name + "': object and detector are required");
  }
  pipeline.Check();
}

namespace {

// The other object's certified estimate on the cloud, or nullopt.
std::optional<PoseEstimate> CertifiedEstimate(const KnownObject& other, const PointSet& cloud, const DepthView& view,
                                              const PointSet* evidence) {
  PointSet keypoints;
  try {
    keypoints = other.detector->Detect(cloud);
  } catch (const Interrupted&) {
    throw;
  } catch (const std::exception&) {
    return std::nullopt;   // no keypoints, no pose: this object certifies nothing here
  }
  if (keypoints.cols() != other.object->num_keypoints()) return std::nullopt;
  PipelineOptions pipeline = other.pipeline;
  pipeline.certificate.global.reestimate = false;   // the first estimate only (identity_check.hpp)
  const CertificateOptions& certificate = pipeline.certificate;
  const std::optional<FreeSpaceTest> free_space =
      MakeFreeSpaceTest(*other.object, view, certificate.free_space, certificate.eps_oc);
  PoseEstimate estimate =
      EstimateAndCertify(*other.object, cloud, keypoints, pipeline, free_space ? &*free_space : nullptr, evidence);
  if (!estimate.certified()) return std::nullopt;
  return estimate;
}

}  // namespace

IdentityCheck CheckIdentity(const std::vector<KnownObject>& others, const PointSet& cloud, const DepthView& view,
                            const PointSet* evidence) {
  IdentityCheck check;
  check.checked = true;
  for (const KnownObject& other : others) {
    ThrowIfInterrupted();
    ++check.objects_tried;
    const std::optional<PoseEstimate> estimate = CertifiedEstimate(other, cloud, view, evidence);
    if (!estimate) continue;
    check.passed = false;
    check.rival = other.name;
    check.rival_oc_distance = estimate->certificate.oc.budget_distance;
    check.rival_scene_from_model = estimate->scene_from_model;
    break;
  }
  return check;
}

}  // namespace c3po
