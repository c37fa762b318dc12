// The parts of a certificate that refused a pose, and their evidence.
#include "c3po/method/refusal.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <stdexcept>

namespace c3po {
namespace {

// The local part failed and the weak-motion check did not discharge it.
bool LocalFailed(const NonDegeneracy& nd) {
  if (!nd.local_checked || nd.local.passed) return false;
  return !(nd.weak_motion_checked && nd.weak_motion.passed);
}

std::string Format(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string Format(const char* format, ...) {
  char text[256];
  va_list args;
  va_start(args, format);
  std::vsnprintf(text, sizeof text, format, args);
  va_end(args);
  return text;
}

std::string Evidence(CertificatePart part, const Certificate& c) {
  const ObservableCorrectness& oc = c.oc;
  const NonDegeneracy& nd = c.nd;
  const FreeSpace& f = c.free_space;
  switch (part) {
    case CertificatePart::kOcPoints:
      if (oc.point_distances.size() == 0) return "no input points";
      return Format("%d of %d points at >= eps_oc %.3g (budget %d)", oc.outlier_count,
                    static_cast<int>(oc.point_distances.size()), oc.eps_oc, oc.max_outliers);
    case CertificatePart::kOcKeypoints:
      return Format("keypoints %.3g from the posed model's (eps_oc %.3g)", oc.max_keypoint_distance, oc.eps_oc);
    case CertificatePart::kFreeSpace:
      return Format("%d of %d measured pixels see behind the posed model (tolerance %.3g, limit %.3g)",
                    f.violations, f.measured, f.tolerance, f.limit);
    case CertificatePart::kSupport:
      return Format("%d of %d model points below the table", f.through_support, f.support_points);
    case CertificatePart::kMask:
      return Format("%d of %d measured pixels show the posed surface outside the mask (limit %.3g)",
                    f.seen_outside_mask, f.measured, f.mask_limit);
    case CertificatePart::kUncovered:
      return Format("%d of %d mask pixels at the posed model's depth lie outside its silhouette (limit %.3g)",
                    f.mask_uncovered, f.mask_at_depth, f.uncovered_limit);
    case CertificatePart::kNdSets: {
      if (nd.set_min_support.empty()) return "no input points";
      const int best = *std::max_element(nd.set_min_support.begin(), nd.set_min_support.end());
      return Format("no indicator set supported (best set's weakest keypoint: %d points within delta_nd %.3g, "
                    "needs > %d)", best, nd.delta_nd, nd.max_outliers);
    }
    case CertificatePart::kNdLocal:
      return Format("%d motion%s the accepted points do not constrain (lambda_min %.3g, %d points)",
                    nd.local.weak_motions, nd.local.weak_motions == 1 ? "" : "s", nd.local.min_eigenvalue,
                    nd.local.observed_points);
    case CertificatePart::kNdWeakMotion:
      return Format("the pose moved %.3g along its unconstrained motion fits too (%.3g away, %d points at >= "
                    "eps_oc)", nd.weak_motion.rival_step, nd.weak_motion.rival_hausdorff,
                    nd.weak_motion.rival_outliers);
    case CertificatePart::kNdGlobal:
      if (nd.global.rival_angle_deg == 0.0) {   // the estimate's own refit (RivalHypotheses)
        return Format("the corrector moves the pose %.3g away, where it leaves %d points at >= eps_oc (rival "
                      "distance %.3g)", nd.global.rival_hausdorff, nd.global.rival_outliers,
                      nd.global.rival_distance);
      }
      return Format("a pose %.3g away (%.0f deg about axis %d) leaves %d points at >= eps_oc (rival distance %.3g)",
                    nd.global.rival_hausdorff, nd.global.rival_angle_deg, nd.global.rival_axis,
                    nd.global.rival_outliers, nd.global.rival_distance);
    case CertificatePart::kIdentity:
      return Format("%.200s is certified on the cloud too (its oc distance %.3g; %d other object%s tried)",
                    c.identity.rival.c_str(), c.identity.rival_oc_distance, c.identity.objects_tried,
                    c.identity.objects_tried == 1 ? "" : "s");
  }
  throw std::logic_error("unknown certificate part");
}

}  // namespace

const char* ToString(CertificatePart part) {
  switch (part) {
    case CertificatePart::kOcPoints: return "oc";
    case CertificatePart::kOcKeypoints: return "oc_keypoints";
    case CertificatePart::kFreeSpace: return "free_space";
    case CertificatePart::kSupport: return "support";
    case CertificatePart::kMask: return "mask";
    case CertificatePart::kUncovered: return "uncovered";
    case CertificatePart::kNdSets: return "nd_sets";
    case CertificatePart::kNdLocal: return "nd_local";
    case CertificatePart::kNdWeakMotion: return "nd_weak_motion";
    case CertificatePart::kNdGlobal: return "nd_global";
    case CertificatePart::kIdentity: return "identity";
  }
  return "?";
}

std::vector<CertificatePart> RefusedBy(const Certificate& c) {
  std::vector<CertificatePart> parts;
  if (!c.oc.points_passed) parts.push_back(CertificatePart::kOcPoints);
  if (!c.oc.keypoints_passed) parts.push_back(CertificatePart::kOcKeypoints);
  if (c.free_space.refutes() && !c.free_space.silhouette_passed) parts.push_back(CertificatePart::kFreeSpace);
  if (c.free_space.refutes() && !c.free_space.support_passed) parts.push_back(CertificatePart::kSupport);
  if (c.free_space.refutes() && !c.free_space.mask_passed) parts.push_back(CertificatePart::kMask);
  if (c.free_space.refutes() && !c.free_space.uncovered_passed) parts.push_back(CertificatePart::kUncovered);
  const NonDegeneracy& nd = c.nd;
  if (!nd.sets_passed) parts.push_back(CertificatePart::kNdSets);
  if (LocalFailed(nd)) {
    parts.push_back(nd.weak_motion_checked ? CertificatePart::kNdWeakMotion : CertificatePart::kNdLocal);
  }
  if (nd.global_checked && !nd.global.passed) parts.push_back(CertificatePart::kNdGlobal);
  if (c.identity.checked && !c.identity.passed) parts.push_back(CertificatePart::kIdentity);
  return parts;
}

std::vector<std::string> RefusedByNames(const PoseEstimate& estimate) {
  if (!estimate.ok()) return {"registration"};
  std::vector<std::string> names;
  for (const CertificatePart part : RefusedBy(estimate.certificate)) names.emplace_back(ToString(part));
  return names;
}

std::vector<RefusalCount> CountRefusals(const std::vector<CloudOutcome>& outcomes) {
  std::vector<RefusalCount> counts = {{"registration"}};
  for (std::size_t k = 0; k < kCertificatePartCount; ++k) counts.push_back({ToString(static_cast<CertificatePart>(k))});
  for (const CloudOutcome& outcome : outcomes) {
    if (!outcome.processed() || outcome.estimate.certified()) continue;
    const std::vector<std::string> names = RefusedByNames(outcome.estimate);
    for (RefusalCount& count : counts) {
      const auto at = std::find(names.begin(), names.end(), count.name);
      count.failed += at != names.end();
      count.first += at == names.begin() && at != names.end();
    }
  }
  return counts;
}

std::string RefusalSummary(const Certificate& c) {
  std::string summary;
  for (const CertificatePart part : RefusedBy(c)) {
    if (!summary.empty()) summary += "; ";
    summary += std::string(ToString(part)) + ": " + Evidence(part, c);
  }
  return summary;
}

}  // namespace c3po
