// png_io: libspng-based single-channel PNG reading/writing, checked against
// libpng (an independent decoder/encoder) and on damaged files.
#include <doctest/doctest.h>
#include <png.h>

#include <random>
#include <string>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/io/png_io.hpp"
#include "test_helpers.hpp"

namespace {

c3po::Image RandomImage(int width, int height, int depth, unsigned seed) {
  c3po::Image image(width, height, depth);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> value(0, depth == 16 ? 65535 : 255);
  for (auto& p : image.pixels) p = static_cast<std::uint16_t>(value(rng));
  return image;
}

// libpng's classic read API on a memory buffer, no transforms.
struct MemReader {
  const std::string* bytes;
  std::size_t offset = 0;
};
void ReadCallback(png_structp png, png_bytep out, png_size_t length) {
  auto* reader = static_cast<MemReader*>(png_get_io_ptr(png));
  if (reader->offset + length > reader->bytes->size()) png_error(png, "short");
  std::copy(reader->bytes->data() + reader->offset, reader->bytes->data() + reader->offset + length,
            out);
  reader->offset += length;
}

// The image libpng decodes (rows of big-endian 16-bit or 8-bit samples).
c3po::Image LibpngDecode(const std::string& bytes) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  c3po::Image image;
  MemReader reader{&bytes};
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    FAIL("libpng could not decode");
    return image;
  }
  png_set_read_fn(png, &reader, ReadCallback);
  png_read_info(png, info);
  const int width = static_cast<int>(png_get_image_width(png, info));
  const int height = static_cast<int>(png_get_image_height(png, info));
  const int depth = png_get_bit_depth(png, info);
  REQUIRE(png_get_color_type(png, info) == PNG_COLOR_TYPE_GRAY);
  image = c3po::Image(width, height, depth);
  std::vector<png_byte> row(png_get_rowbytes(png, info));
  for (int v = 0; v < height; ++v) {
    png_read_row(png, row.data(), nullptr);
    for (int u = 0; u < width; ++u) {
      image.at(u, v) = depth == 16 ? static_cast<std::uint16_t>((row[2 * u] << 8) | row[2 * u + 1])
                                   : row[u];
    }
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

void WriteCallback(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<char*>(data), length);
}
void FlushCallback(png_structp) {}

// Encodes with libpng: `colour_type`/`depth` as given; samples from `image`
// (for RGB each sample repeated three times); `interlace` Adam7.
std::string LibpngEncode(const c3po::Image& image, int colour_type, int depth, bool interlace) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  std::string out;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    FAIL("libpng could not encode");
    return out;
  }
  png_set_write_fn(png, &out, WriteCallback, FlushCallback);
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.width),
               static_cast<png_uint_32>(image.height), depth, colour_type,
               interlace ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (colour_type == PNG_COLOR_TYPE_PALETTE) {
    png_color palette[2] = {{0, 0, 0}, {255, 255, 255}};
    png_set_PLTE(png, info, palette, 2);
  }
  png_write_info(png, info);
  const int channels = colour_type == PNG_COLOR_TYPE_RGB ? 3 : 1;
  const int bytes_per_sample = depth == 16 ? 2 : 1;
  std::vector<std::vector<png_byte>> rows(static_cast<std::size_t>(image.height));
  std::vector<png_bytep> pointers;
  for (int v = 0; v < image.height; ++v) {
    auto& row = rows[static_cast<std::size_t>(v)];
    row.assign(static_cast<std::size_t>(image.width * channels * bytes_per_sample + 1), 0);
    for (int u = 0; u < image.width; ++u) {
      const std::uint16_t value = image.at(u, v);
      for (int c = 0; c < channels; ++c) {
        const int index = u * channels + c;
        if (depth == 16) {
          row[static_cast<std::size_t>(2 * index)] = static_cast<png_byte>(value >> 8);
          row[static_cast<std::size_t>(2 * index + 1)] = static_cast<png_byte>(value & 0xff);
        } else if (depth == 8) {
          row[static_cast<std::size_t>(index)] = static_cast<png_byte>(value);
        } else {  // packed, MSB first
          const int per_byte = 8 / depth;
          const int shift = 8 - depth * (1 + index % per_byte);
          row[static_cast<std::size_t>(index / per_byte)] |= static_cast<png_byte>(value << shift);
        }
      }
    }
    pointers.push_back(row.data());
  }
  png_write_image(png, pointers.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

// PNG's CRC-32 (ISO 3309, polynomial 0xedb88320), bitwise.
std::uint32_t Crc32(const char* data, std::size_t length) {
  std::uint32_t crc = 0xffffffffu;
  for (std::size_t i = 0; i < length; ++i) {
    crc ^= static_cast<unsigned char>(data[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return crc ^ 0xffffffffu;
}

std::string ErrorOf(const std::string& bytes) {
  try {
    c3po::DecodePng(bytes, "img.png");
  } catch (const c3po::InputError& error) {
    return error.what();
  }
  return "";
}

}  // namespace

TEST_CASE("8- and 16-bit random images round-trip, and libpng agrees both ways") {
  for (int depth : {8, 16}) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
      const int width = 1 + static_cast<int>(seed * 37 % 97), height = 1 + static_cast<int>(seed * 11 % 53);
      const c3po::Image image = RandomImage(width, height, depth, seed);
      const std::string ours = c3po::EncodePng(image);
      const c3po::Image back = c3po::DecodePng(ours, "mem.png");
      CHECK(back.width == width);
      CHECK(back.height == height);
      CHECK(back.bit_depth == depth);
      CHECK(back.pixels == image.pixels);
      // libpng decodes what we wrote ...
      CHECK(LibpngDecode(ours).pixels == image.pixels);
      // ... and we decode what libpng wrote (plain and interlaced).
      for (bool interlace : {false, true}) {
        const c3po::Image theirs =
            c3po::DecodePng(LibpngEncode(image, PNG_COLOR_TYPE_GRAY, depth, interlace), "lib.png");
        CHECK(theirs.bit_depth == depth);
        CHECK(theirs.pixels == image.pixels);
      }
    }
  }
}

TEST_CASE("1-, 2- and 4-bit greyscale read as 8-bit with their stored values") {
  for (int depth : {1, 2, 4}) {
    c3po::Image image(13, 5, 8);
    std::mt19937 rng(static_cast<unsigned>(depth));
    for (auto& p : image.pixels) p = static_cast<std::uint16_t>(rng() % (1u << depth));
    const c3po::Image read =
        c3po::DecodePng(LibpngEncode(image, PNG_COLOR_TYPE_GRAY, depth, false), "packed.png");
    CHECK(read.bit_depth == 8);
    CHECK(read.pixels == image.pixels);
  }
}

TEST_CASE("WritePng/ReadPng through a file, ReadDepthPng wants 16 bits") {
  c3po::test::TempDir dir("png_io");
  const c3po::Image depth = RandomImage(40, 30, 16, 9);
  c3po::WritePng(dir / "depth.png", depth);
  CHECK(c3po::ReadDepthPng(dir / "depth.png").pixels == depth.pixels);
  const c3po::Image mask = RandomImage(40, 30, 8, 10);
  c3po::WritePng(dir / "mask.png", mask);
  CHECK(c3po::ReadPng(dir / "mask.png").pixels == mask.pixels);
  try {
    c3po::ReadDepthPng(dir / "mask.png");
    FAIL("8-bit depth accepted");
  } catch (const c3po::InputError& error) {
    const std::string message = error.what();
    CHECK(message.find(dir / "mask.png") == 0);
    CHECK(message.find("8-bit PNG given as depth") != std::string::npos);
  }
  CHECK_THROWS_AS(c3po::ReadPng(dir / "missing.png"), c3po::InputError);
}

TEST_CASE("RGB, palette, truncated, corrupt and empty files are one-line InputErrors") {
  const c3po::Image image = RandomImage(20, 10, 8, 3);
  const std::string rgb = ErrorOf(LibpngEncode(image, PNG_COLOR_TYPE_RGB, 8, false));
  CHECK(rgb.find("img.png: RGB PNG") == 0);
  c3po::Image binary(20, 10, 8);
  for (std::size_t i = 0; i < binary.pixels.size(); i += 3) binary.pixels[i] = 1;
  const std::string palette = ErrorOf(LibpngEncode(binary, PNG_COLOR_TYPE_PALETTE, 8, false));
  CHECK(palette.find("img.png: palette") == 0);

  const std::string good = c3po::EncodePng(RandomImage(64, 64, 16, 4));
  std::vector<std::string> bad = {"", "not a png at all", good.substr(0, 8), good.substr(0, 30),
                                  good.substr(0, good.size() / 2), good.substr(0, good.size() - 12)};
  std::string flipped = good;
  flipped[good.size() / 2] = static_cast<char>(flipped[good.size() / 2] ^ 0x5a);
  bad.push_back(flipped);
  for (const std::string& bytes : bad) {
    const std::string message = ErrorOf(bytes);
    INFO("input of ", bytes.size(), " bytes");
    CHECK(message.find("img.png: ") == 0);
    CHECK(message.find('\n') == std::string::npos);
  }
}

TEST_CASE("a header asking for a huge image is refused before allocating it") {
  // A 1 x 1 16-bit PNG whose IHDR is patched to claim 60000 x 60000 (then
  // 3000 x 3000), with the chunk's CRC recomputed so only the size lies.
  std::string png = c3po::EncodePng(RandomImage(1, 1, 16, 5));
  auto put32 = [&](std::size_t at, std::uint32_t value) {
    for (int i = 0; i < 4; ++i) png[at + static_cast<std::size_t>(i)] = static_cast<char>(value >> (24 - 8 * i));
  };
  put32(16, 60000);  // IHDR data starts at 16: width, height
  put32(20, 60000);
  const std::uint32_t crc = Crc32(png.data() + 12, 17);  // "IHDR" + 13 bytes
  put32(29, crc);
  const std::string message = ErrorOf(png);
  CHECK(message.find("img.png: ") == 0);
  CHECK(message.find("60000") != std::string::npos);
  put32(16, 3000);
  put32(20, 3000);
  put32(29, Crc32(png.data() + 12, 17));
  CHECK(ErrorOf(png).find("truncated PNG") != std::string::npos);
}

TEST_CASE("EncodePng refuses inconsistent images") {
  c3po::Image image(4, 4, 8);
  image.pixels[3] = 300;
  CHECK_THROWS_AS(c3po::EncodePng(image), std::invalid_argument);
  image.pixels.pop_back();
  CHECK_THROWS_AS(c3po::EncodePng(image), std::invalid_argument);
  CHECK_THROWS_AS(c3po::Image(2, 2, 12), std::invalid_argument);
}
