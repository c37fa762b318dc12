#pragma once
// Single-channel PNG images (depth images, masks, label images) through
// libspng (Debian libspng-dev; third_party_notes/libspng.md). Only greyscale
// PNGs without alpha are images here: an RGB, palette or grey+alpha file is an
// InputError naming the file, never silently converted.
#include <cstdint>
#include <string>
#include <vector>

namespace c3po {

// A single-channel image, row-major (pixel (u, v) = column u, row v is
// pixels[v * width + u]). bit_depth is 8 or 16: the range of the samples
// (0..255 or 0..65535); greyscale PNGs of 1, 2 or 4 bits are read as 8-bit
// with their stored sample values (not rescaled).
struct Image {
  int width = 0;
  int height = 0;
  int bit_depth = 8;
  std::vector<std::uint16_t> pixels;

  Image() = default;
  Image(int width_, int height_, int bit_depth_);  // zero-filled; throws std::invalid_argument
  std::uint16_t at(int u, int v) const { return pixels[static_cast<std::size_t>(v) * width + u]; }
  std::uint16_t& at(int u, int v) { return pixels[static_cast<std::size_t>(v) * width + u]; }
  bool SameSize(const Image& other) const { return width == other.width && height == other.height; }
};

// Largest image read (pixels): 2^27 (e.g. 16384 x 8192). A header asking for
// more is an InputError, not an allocation.
inline constexpr std::size_t kMaxImagePixels = std::size_t{1} << 27;

// Decodes PNG bytes; `name` labels errors ("name: ..."). Throws InputError.
Image DecodePng(const std::string& bytes, const std::string& name);
// Reads a PNG file (DecodePng of its bytes).
Image ReadPng(const std::string& path);
// A depth image: like ReadPng, but anything other than a 16-bit single-channel
// PNG is an InputError ("8-bit PNG given as depth image; expected 16-bit ...").
Image ReadDepthPng(const std::string& path);

// Encodes a greyscale PNG of the image's bit depth. Throws std::invalid_argument
// for an inconsistent Image (size, depth, a sample above the depth's range).
std::string EncodePng(const Image& image);
// Writes EncodePng(image) atomically (WriteFileAtomically).
void WritePng(const std::string& path, const Image& image);

}  // namespace c3po
