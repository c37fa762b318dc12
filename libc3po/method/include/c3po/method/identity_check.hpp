#pragma once
// Identity among known objects (docs/method.md "Identity among known
// objects"). The paper certifies the pose of one known object: it assumes the
// cloud shows that object. When the scene may hold other known objects (a BOP
// dataset's models, a bin of parts), a cloud of another object whose shape
// agrees with this one's within eps_oc (two boxes a few millimetres apart)
// passes every geometric test: the certificate's claim is true of the shape
// but not of the identity. This check gives the cloud to each other object's
// own certifier (its detector, its thresholds, the same budget and frame)
// and fails when one of them certifies it too: the cloud does not say which
// object it shows, so neither pose is certified.
#include <string>
#include <vector>

#include "c3po/method/certificate.hpp"
#include "c3po/method/detector.hpp"
#include "c3po/method/free_space.hpp"
#include "c3po/method/pipeline.hpp"
#include "c3po/object/object_model.hpp"

namespace c3po {

struct KnownObject {
  std::string name;                     // how the evidence names it (its file)
  const ObjectModel* object = nullptr;
  const Detector* detector = nullptr;   // its keypoints (never null)
  PipelineOptions pipeline;             // its certifier: its own eps_oc and delta_nd
  void Check() const;                   // throws std::invalid_argument
};

// Runs each other object's certifier on `cloud` (`evidence`: the cloud the
// certificates judge when it is another, pipeline.hpp; `view`: the depth
// frame for the free-space test, invalid for clouds) in order, and stops at
// the first one certified. Each certifier judges its detector's first
// estimate: re-estimation (GlobalUniquenessOptions::reestimate) is off for
// them, since restarting every other object about 13 axes on every segment
// costs tens of seconds per pose (measured: docs/method.md). A detector
// that fails on the cloud certifies nothing. Interrupted propagates.
IdentityCheck CheckIdentity(const std::vector<KnownObject>& others, const PointSet& cloud, const DepthView& view,
                            const PointSet* evidence = nullptr);

}  // namespace c3po
