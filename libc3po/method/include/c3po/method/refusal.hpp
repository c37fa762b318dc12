#pragma once
// Why a certificate refused a pose: the parts that failed, in the order the
// pipeline decides them, and their evidence in one line of words
// (docs/method.md "Why a pose was refused"). `certify` prints them, its JSON
// lines carry the parts (`refused_by`), the evaluation report shows them
// next to each rejected example.
#include <cstddef>
#include <string>
#include <vector>

#include "c3po/method/certificate.hpp"
#include "c3po/method/certify_batch.hpp"
#include "c3po/method/pipeline.hpp"

namespace c3po {

enum class CertificatePart {
  kOcPoints,       // more than m input points at >= eps_oc (or no points)
  kOcKeypoints,    // corrected keypoints disagree with the posed model's
  kFreeSpace,      // depth-image inputs: the camera saw through the posed model
  kSupport,        // depth-image inputs: the posed model reaches into the table
  kMask,           // depth-image inputs: the posed model claims surface seen outside the segment's mask
  kUncovered,      // depth-image inputs: the mask shows surface at the model's depth the posed model does not cover
  kNdSets,         // no indicator set is supported
  kNdLocal,        // a motion the accepted points do not constrain (first order)
  kNdWeakMotion,   // the single unseen motion leads to a pose that fits too
  kNdGlobal,       // a far pose (rival) explains the points too
  kIdentity,       // another known object is certified on the cloud too (identity_check.hpp)
};
inline constexpr std::size_t kCertificatePartCount = static_cast<std::size_t>(CertificatePart::kIdentity) + 1;

// "oc", "oc_keypoints", "free_space", "support", "mask", "uncovered", "nd_sets", "nd_local",
// "nd_weak_motion", "nd_global", "identity".
const char* ToString(CertificatePart part);

// The failed parts in the order above; empty iff certificate.certified().
// The weak-motion check replaces the local part when it ran; the global
// search runs only when everything else passed, so it is then the only part;
// so does the identity check (after the global search).
std::vector<CertificatePart> RefusedBy(const Certificate& certificate);

// The names of RefusedBy(estimate.certificate), or {"registration"} when the
// estimate has no pose (the corrector's registration failed): what `certify`
// writes as `refused_by`.
std::vector<std::string> RefusedByNames(const PoseEstimate& estimate);

// Over the processed, uncertified outcomes of a batch, per name in the order
// "registration", then the parts': how many poses it refused (`failed`; a
// pose may fail several parts) and how many it refused first (`first`; these
// sum to the refused poses). Every name is listed, counts may be 0.
struct RefusalCount {
  std::string name;
  int failed = 0;
  int first = 0;
};
std::vector<RefusalCount> CountRefusals(const std::vector<CloudOutcome>& outcomes);

// "" when certified, else one clause per failed part joined by "; ", each
// with its evidence (object units), e.g. "nd_global: a pose 0.032 away
// (180 deg about axis 0) leaves 21 points at >= eps_oc" (axis: a ReestimateAxes column, 0-2 the principal axes).
std::string RefusalSummary(const Certificate& certificate);

}  // namespace c3po
