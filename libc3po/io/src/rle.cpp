// COCO RLE masks (rle.hpp).
#include "c3po/io/rle.hpp"

#include <cstdio>

#include "c3po/base/error.hpp"

namespace c3po {

RleCounts ParseRleString(const std::string& text, const std::string& name) {
  RleCounts counts;
  std::size_t p = 0;
  while (p < text.size()) {
    std::int64_t x = 0;
    int k = 0;
    bool more = true;
    while (more) {
      if (p >= text.size()) throw InputError(name, "malformed RLE: string ends inside a run");
      const int c = static_cast<unsigned char>(text[p]) - 48;
      if (c < 0 || c > 63) {
        char code[8];
        std::snprintf(code, sizeof code, "0x%02x", static_cast<unsigned char>(text[p]));
        throw InputError(name, std::string("malformed RLE: character ") + code + " at " + std::to_string(p) +
                                   " (expected '0'..'o')");
      }
      if (k >= 12) throw InputError(name, "malformed RLE: run too long at " + std::to_string(p));
      x |= static_cast<std::int64_t>(c & 0x1f) << (5 * k);
      more = (c & 0x20) != 0;
      ++p;
      ++k;
      if (!more && (c & 0x10)) x |= static_cast<std::int64_t>(~std::uint64_t{0} << (5 * k));   // sign-extend
    }
    if (counts.size() > 2) x += counts[counts.size() - 2];
    if (x < 0) throw InputError(name, "malformed RLE: negative run " + std::to_string(x) + " (run " + std::to_string(counts.size()) + ")");
    counts.push_back(x);
  }
  return counts;
}

std::string RleString(const RleCounts& counts) {
  std::string out;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    std::int64_t x = counts[i];
    if (i > 2) x -= counts[i - 2];
    bool more = true;
    while (more) {
      int c = static_cast<int>(x & 0x1f);
      x >>= 5;   // arithmetic shift
      more = (c & 0x10) ? x != -1 : x != 0;
      if (more) c |= 0x20;
      out += static_cast<char>(c + 48);
    }
  }
  return out;
}

Mask DecodeRle(int height, int width, const RleCounts& counts, const std::string& name) {
  if (height <= 0 || width <= 0 || static_cast<std::size_t>(height) * static_cast<std::size_t>(width) > kMaxImagePixels) {
    throw InputError(name, "malformed RLE: bad size " + std::to_string(height) + " x " + std::to_string(width));
  }
  const std::int64_t total = static_cast<std::int64_t>(height) * width;
  std::int64_t sum = 0;
  for (std::size_t i = 0; i < counts.size(); ++i) {
    if (counts[i] < 0) throw InputError(name, "malformed RLE: negative run");
    if (counts[i] > total - sum) {
      throw InputError(name, "malformed RLE: runs cover more than " + std::to_string(height) + " x " + std::to_string(width) + " pixels");
    }
    sum += counts[i];
  }
  if (sum != total) {
    throw InputError(name, "malformed RLE: runs cover " + std::to_string(sum) + " pixels, size " +
                               std::to_string(height) + " x " + std::to_string(width) + " has " + std::to_string(total));
  }
  Mask mask{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(total), 0)};
  std::int64_t index = 0;   // column-major pixel index
  for (std::size_t i = 0; i < counts.size(); ++i) {
    if (i % 2 == 1) {
      for (std::int64_t j = index; j < index + counts[i]; ++j) {
        const std::int64_t u = j / height, v = j % height;
        mask.inside[static_cast<std::size_t>(v * width + u)] = 1;
      }
    }
    index += counts[i];
  }
  return mask;
}

RleCounts EncodeRle(const Mask& mask) {
  RleCounts counts;
  std::uint8_t current = 0;
  std::int64_t run = 0;
  for (int u = 0; u < mask.width; ++u) {
    for (int v = 0; v < mask.height; ++v) {
      const std::uint8_t value = mask.at(u, v) ? 1 : 0;
      if (value != current) {
        counts.push_back(run);
        run = 0;
        current = value;
      }
      ++run;
    }
  }
  counts.push_back(run);
  return counts;
}

}  // namespace c3po
