// Single-channel PNG reading and writing through libspng (png_io.hpp).
#include "c3po/io/png_io.hpp"

#include <spng.h>

#include <cstring>
#include <memory>
#include <stdexcept>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"

namespace c3po {

namespace {

struct CtxDeleter {
  void operator()(spng_ctx* ctx) const { spng_ctx_free(ctx); }
};
using CtxPtr = std::unique_ptr<spng_ctx, CtxDeleter>;

const char* ColourTypeName(int colour_type) {
  switch (colour_type) {
    case SPNG_COLOR_TYPE_GRAYSCALE: return "greyscale";
    case SPNG_COLOR_TYPE_TRUECOLOR: return "RGB";
    case SPNG_COLOR_TYPE_INDEXED: return "palette (indexed colour)";
    case SPNG_COLOR_TYPE_GRAYSCALE_ALPHA: return "greyscale+alpha";
    case SPNG_COLOR_TYPE_TRUECOLOR_ALPHA: return "RGBA";
    default: return "unknown colour type";
  }
}

// zlib's best ratio is about 1032:1; a header asking for far more image data
// than the file could inflate to is truncated or lying, refused before any
// allocation of that size.
constexpr std::size_t kMaxInflateRatio = 1100;

}  // namespace

Image::Image(int width_, int height_, int bit_depth_)
    : width(width_), height(height_), bit_depth(bit_depth_) {
  if (width < 0 || height < 0 || (bit_depth != 8 && bit_depth != 16)) {
    throw std::invalid_argument("Image: bad size or bit depth");
  }
  pixels.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
}

namespace {

// The raw scanlines of a single-channel PNG (and its header), after the size and truncation checks.
std::vector<unsigned char> DecodeGreyscaleRows(const std::string& bytes, const std::string& name, spng_ihdr* ihdr) {
  CtxPtr ctx(spng_ctx_new(0));
  if (!ctx) throw std::bad_alloc();
  spng_set_image_limits(ctx.get(), 1u << 20, 1u << 20);
  spng_set_chunk_limits(ctx.get(), std::size_t{1} << 26, std::size_t{1} << 26);
  if (int err = spng_set_png_buffer(ctx.get(), bytes.data(), bytes.size())) {
    throw InputError(name, std::string("not a PNG: ") + spng_strerror(err));
  }
  if (int err = spng_get_ihdr(ctx.get(), ihdr)) {
    throw InputError(name, std::string("not a readable PNG: ") + spng_strerror(err));
  }
  if (ihdr->color_type != SPNG_COLOR_TYPE_GRAYSCALE) {
    throw InputError(name, std::string(ColourTypeName(ihdr->color_type)) +
                               " PNG; expected a single-channel (greyscale) image");
  }
  const std::size_t width = ihdr->width, height = ihdr->height;
  if (width == 0 || height == 0) throw InputError(name, "PNG of zero size");
  if (width * height > kMaxImagePixels) {
    throw InputError(name, "PNG of " + std::to_string(width) + " x " + std::to_string(height) +
                               " pixels is larger than the limit of " +
                               std::to_string(kMaxImagePixels) + " pixels");
  }
  std::size_t raw_size = 0;
  if (int err = spng_decoded_image_size(ctx.get(), SPNG_FMT_RAW, &raw_size)) {
    throw InputError(name, std::string("not a readable PNG: ") + spng_strerror(err));
  }
  if (raw_size > kMaxInflateRatio * bytes.size() + 4096) {
    throw InputError(name, "truncated PNG: " + std::to_string(width) + " x " +
                               std::to_string(height) + " pixels cannot come from " +
                               std::to_string(bytes.size()) + " bytes");
  }
  std::vector<unsigned char> raw(raw_size);
  if (int err = spng_decode_image(ctx.get(), raw.data(), raw.size(), SPNG_FMT_RAW, 0)) {
    throw InputError(name, std::string("damaged PNG: ") + spng_strerror(err));
  }
  // The chunks after the image data, up to IEND: a file cut after its pixels
  // is truncated all the same.
  if (int err = spng_decode_chunks(ctx.get())) {
    throw InputError(name, std::string("truncated or damaged PNG after the image data: ") +
                               spng_strerror(err));
  }
  return raw;
}

// Scanlines of 1, 2, 4, 8 or 16 bits per pixel (PNG order: big-endian, packed from the most
// significant bit) into pixels.
void UnpackRows(const std::vector<unsigned char>& raw, std::size_t width, std::size_t height, int depth,
                const std::string& name, Image* image) {
  const std::size_t stride = (width * static_cast<std::size_t>(depth) + 7) / 8;
  if (raw.size() < stride * height) throw InputError(name, "damaged PNG: short image data");
  for (std::size_t v = 0; v < height; ++v) {
    const unsigned char* row = raw.data() + v * stride;
    std::uint16_t* out = image->pixels.data() + v * width;
    if (depth == 16) {
      for (std::size_t u = 0; u < width; ++u) {
        out[u] = static_cast<std::uint16_t>((row[2 * u] << 8) | row[2 * u + 1]);  // big-endian
      }
    } else if (depth == 8) {
      for (std::size_t u = 0; u < width; ++u) out[u] = row[u];
    } else {  // 1, 2 or 4 bits, packed from the most significant bit
      const unsigned per_byte = 8u / static_cast<unsigned>(depth);
      const unsigned mask = (1u << depth) - 1u;
      for (std::size_t u = 0; u < width; ++u) {
        const unsigned shift = 8u - static_cast<unsigned>(depth) * (1u + u % per_byte);
        out[u] = static_cast<std::uint16_t>((row[u / per_byte] >> shift) & mask);
      }
    }
  }
}

}  // namespace

Image DecodePng(const std::string& bytes, const std::string& name) {
  spng_ihdr ihdr{};
  const std::vector<unsigned char> raw = DecodeGreyscaleRows(bytes, name, &ihdr);
  const int depth = ihdr.bit_depth;
  Image image(static_cast<int>(ihdr.width), static_cast<int>(ihdr.height), depth == 16 ? 16 : 8);
  UnpackRows(raw, ihdr.width, ihdr.height, depth, name, &image);
  return image;
}

Image ReadPng(const std::string& path) { return DecodePng(ReadFileToString(path), path); }

Image ReadDepthPng(const std::string& path) {
  Image image = ReadPng(path);
  if (image.bit_depth != 16) {
    throw InputError(path, "8-bit PNG given as depth image; expected a 16-bit single-channel PNG "
                           "(value x depth_scale = mm)");
  }
  return image;
}

std::string EncodePng(const Image& image) {
  if (image.width <= 0 || image.height <= 0 || (image.bit_depth != 8 && image.bit_depth != 16) ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height) {
    throw std::invalid_argument("EncodePng: inconsistent image");
  }
  // SPNG_FMT_PNG takes the file's sample layout with 16-bit samples in host
  // byte order (spng.h: only SPNG_FMT_RAW is big-endian).
  const std::size_t count = image.pixels.size();
  std::vector<unsigned char> raw(count * static_cast<std::size_t>(image.bit_depth / 8));
  if (image.bit_depth == 8) {
    for (std::size_t i = 0; i < count; ++i) {
      if (image.pixels[i] > 255) {
        throw std::invalid_argument("EncodePng: sample above 255 in an 8-bit image");
      }
      raw[i] = static_cast<unsigned char>(image.pixels[i]);
    }
  } else {
    std::memcpy(raw.data(), image.pixels.data(), raw.size());
  }
  CtxPtr ctx(spng_ctx_new(SPNG_CTX_ENCODER));
  if (!ctx) throw std::bad_alloc();
  spng_set_option(ctx.get(), SPNG_ENCODE_TO_BUFFER, 1);
  spng_ihdr ihdr{};
  ihdr.width = static_cast<std::uint32_t>(image.width);
  ihdr.height = static_cast<std::uint32_t>(image.height);
  ihdr.bit_depth = static_cast<std::uint8_t>(image.bit_depth);
  ihdr.color_type = SPNG_COLOR_TYPE_GRAYSCALE;
  if (int err = spng_set_ihdr(ctx.get(), &ihdr)) {
    throw std::runtime_error(std::string("EncodePng: ") + spng_strerror(err));
  }
  if (int err = spng_encode_image(ctx.get(), raw.data(), raw.size(), SPNG_FMT_PNG,
                                  SPNG_ENCODE_FINALIZE)) {
    throw std::runtime_error(std::string("EncodePng: ") + spng_strerror(err));
  }
  std::size_t length = 0;
  int err = 0;
  void* buffer = spng_get_png_buffer(ctx.get(), &length, &err);
  if (!buffer) throw std::runtime_error(std::string("EncodePng: ") + spng_strerror(err));
  std::string png(static_cast<const char*>(buffer), length);
  std::free(buffer);
  return png;
}

void WritePng(const std::string& path, const Image& image) {
  WriteFileAtomically(path, EncodePng(image));
}

}  // namespace c3po
