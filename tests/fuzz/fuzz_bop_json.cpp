// libFuzzer target: the BOP/camera JSON readers on arbitrary bytes. The first
// byte picks the reader (scene_camera, scene_gt, detections, targets,
// models_info, camera JSON); detections' RLE masks are decoded as well.
#include "c3po/io/bop.hpp"
#include "c3po/io/camera_io.hpp"
#include "c3po/base/error.hpp"
#include "c3po/io/rle.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text = c3po_fuzz::Bytes(data + 1, size - 1);
  try {
    switch (data[0] % 6) {
      case 0: c3po::ParseSceneCamera(text, "scene_camera.json"); break;
      case 1: c3po::ParseSceneGt(text, "scene_gt.json"); break;
      case 2:
        for (const c3po::BopDetection& d : c3po::ParseDetections(text, "detections.json")) {
          if (static_cast<std::size_t>(d.height) * static_cast<std::size_t>(d.width) <= (1u << 20)) {
            c3po::DecodeRle(d.height, d.width, d.counts, "detections.json");
          }
        }
        break;
      case 3: c3po::ParseTargets(text, "targets.json"); break;
      case 4: c3po::ParseModelsInfo(text, "models_info.json"); break;
      // The --im-id lookup too (an id derived from the selector byte).
      default: c3po::ParseCameraJson(text, "camera.json", std::nullopt,
                                     data[0] >= 128 ? std::optional<int>(data[0] % 8) : std::nullopt); break;
    }
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
