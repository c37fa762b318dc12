#pragma once
// Point clouds: PLY (ASCII, binary little/big endian; float/double; extra
// properties ignored), PCD (ASCII, binary), XYZ text. Readers never trust
// header counts before checking them against the file size.
#include <string>

#include "c3po/base/types.hpp"

namespace c3po {

enum class CloudFormat { kPly, kPcd, kXyz };
// By extension (case-insensitive); throws InputError for an unknown one.
CloudFormat CloudFormatFromPath(const std::string& path);

// Throws InputError("path: line 12: expected 3 coordinates") etc. Rejects
// non-finite coordinates and empty clouds.
PointSet ReadCloud(const std::string& path);
// Parses from memory (for fuzzing and tests); `name` is used in messages.
PointSet ParseCloud(const std::string& bytes, CloudFormat format, const std::string& name);

// Binary little-endian PLY with float x y z, written atomically.
void WritePly(const std::string& path, const PointSet& points);
// Other writers (tests and interoperability).
void WritePlyAscii(const std::string& path, const PointSet& points);
void WritePcd(const std::string& path, const PointSet& points, bool binary);
void WriteXyz(const std::string& path, const PointSet& points);

}  // namespace c3po
