#pragma once
// COCO run-length encoded masks (the "segmentation" of BOP/COCO detections):
// {"size": [height, width], "counts": [...] or "compressed string"}. Runs
// alternate background/object starting with background, over the pixels in
// column-major order (down each column, then the next column). The compressed
// string is COCO's (pycocotools maskApi.c rleToString): each run, minus the
// run two before it from the third run on, in 5-bit groups with a
// continuation bit, offset by 48 ('0').
#include <cstdint>
#include <string>
#include <vector>

#include "c3po/io/segment.hpp"

namespace c3po {

using RleCounts = std::vector<std::int64_t>;

// Throws InputError("name: malformed RLE: ...") for characters outside
// '0'..'o', a run longer than 12 groups, or a negative run.
RleCounts ParseRleString(const std::string& text, const std::string& name);
std::string RleString(const RleCounts& counts);

// Runs must sum to height x width and be >= 0 (InputError otherwise).
Mask DecodeRle(int height, int width, const RleCounts& counts, const std::string& name);
RleCounts EncodeRle(const Mask& mask);

}  // namespace c3po
