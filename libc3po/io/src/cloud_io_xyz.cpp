// XYZ text point clouds: one point per line, at least three columns separated
// by whitespace or commas (extra columns ignored), '#' starts a comment.
#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/io/cloud_io.hpp"
#include "cloud_io_internal.hpp"

namespace c3po {
namespace cloud_detail {

PointSet ParseXyz(std::string_view bytes, const std::string& name) {
  LineReader reader(bytes);
  PointCollector points;
  const auto fail = [&](const std::string& problem) {
    throw InputError(name, "line " + std::to_string(reader.line_number()) + ": " + problem);
  };
  std::string_view line;
  std::vector<std::string_view> tokens;
  while (reader.Next(&line)) {
    const std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    SplitTokens(line, true, &tokens);
    if (tokens.empty()) continue;
    if (tokens.size() < 3) fail("expected 3 coordinates, found " + std::to_string(tokens.size()));
    double xyz[3];
    for (int k = 0; k < 3; ++k) {
      if (!ParseDouble(tokens[k], &xyz[k])) fail(Quote(tokens[k]) + " is not a number");
    }
    if (!AllFinite(xyz[0], xyz[1], xyz[2])) fail("point " + std::to_string(points.size()) + ": non-finite coordinate");
    points.Add(xyz[0], xyz[1], xyz[2]);
  }
  if (points.size() == 0) throw InputError(name, "no points (only blank lines and comments)");
  return points.Take();
}

}  // namespace cloud_detail

void WriteXyz(const std::string& path, const PointSet& points) {
  cloud_detail::CheckWritable(path, points, false);
  WriteFileAtomically(path, [&points](std::ostream& out) {
    for (Eigen::Index i = 0; i < points.cols(); ++i) {
      out << cloud_detail::FormatDouble(points(0, i)) << ' ' << cloud_detail::FormatDouble(points(1, i))
          << ' ' << cloud_detail::FormatDouble(points(2, i)) << '\n';
    }
  });
}

}  // namespace c3po
