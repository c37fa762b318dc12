// Dataset folders: exact manifest round trips, field validation with line
// numbers, and DatasetWriter's all-or-nothing behaviour.
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <thread>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/random.hpp"
#include "c3po/io/cloud_io.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/io/dataset_writer.hpp"
#include "test_helpers.hpp"

using c3po::test::InputErrorOf;

namespace fs = std::filesystem;

namespace {

c3po::PointSet RandomPoints(c3po::Rng& rng, int n) {
  c3po::PointSet points(3, n);
  for (int i = 0; i < n; ++i) points.col(i) = rng.UnitVector() * rng.Uniform(0.01, 1e3);
  return points;
}

c3po::DatasetEntry RandomEntry(c3po::Rng& rng, const std::string& cloud, int keypoints) {
  c3po::DatasetEntry entry;
  entry.cloud = cloud;
  entry.pose = c3po::Pose{rng.Rotation(), RandomPoints(rng, 1).col(0)};
  entry.keypoints = RandomPoints(rng, keypoints);
  entry.detected_keypoints = RandomPoints(rng, keypoints);
  std::vector<bool> visible;
  for (int i = 0; i < keypoints; ++i) visible.push_back(rng.Uniform() < 0.5);
  entry.visible = visible;
  return entry;
}

void CheckSame(const c3po::DatasetEntry& a, const c3po::DatasetEntry& b) {
  CHECK(a.cloud == b.cloud);
  REQUIRE(a.pose.has_value() == b.pose.has_value());
  if (a.pose) {
    CHECK(a.pose->R == b.pose->R);   // bit-exact
    CHECK(a.pose->t == b.pose->t);
  }
  CHECK(a.keypoints.has_value() == b.keypoints.has_value());
  if (a.keypoints && b.keypoints) CHECK(*a.keypoints == *b.keypoints);
  CHECK(a.detected_keypoints.has_value() == b.detected_keypoints.has_value());
  if (a.detected_keypoints && b.detected_keypoints) CHECK(*a.detected_keypoints == *b.detected_keypoints);
  CHECK(a.visible == b.visible);
  CHECK(a.object == b.object);
}

std::vector<std::string> Listing(const std::string& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

std::string ParseError(const std::string& line) {
  return InputErrorOf([&] { c3po::ParseManifestLine(line, "m.jsonl: line 4"); });
}

}  // namespace

TEST_CASE("manifest lines round-trip exactly") {
  c3po::Rng rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const c3po::DatasetEntry entry = RandomEntry(rng, "clouds/" + std::to_string(trial) + ".ply", 1 + trial % 12);
    const std::string line = c3po::ManifestLine(entry);
    CHECK(line.find('\n') == std::string::npos);
    CHECK(line.rfind("{\"cloud\":", 0) == 0);
    CheckSame(c3po::ParseManifestLine(line, "m"), entry);
  }
  c3po::DatasetEntry bare;
  bare.cloud = "only.ply";
  CHECK(c3po::ManifestLine(bare) == "{\"cloud\":\"only.ply\"}");
  CheckSame(c3po::ParseManifestLine(c3po::ManifestLine(bare), "m"), bare);
}

TEST_CASE("a nearly orthonormal R is accepted and projected onto SO(3)") {
  c3po::Rng rng(12);
  const Eigen::Matrix3d R = rng.Rotation();
  // Rotation printed with 7 significant digits, as float-based tools do.
  std::string rows;
  for (int r = 0; r < 3; ++r) {
    char buffer[128];
    std::snprintf(buffer, sizeof buffer, "[%.7g,%.7g,%.7g]", R(r, 0), R(r, 1), R(r, 2));
    rows += (r ? "," : "") + std::string(buffer);
  }
  const auto entry = c3po::ParseManifestLine("{\"cloud\":\"a.ply\",\"R\":[" + rows + "],\"t\":[0,0,1]}", "m");
  REQUIRE(entry.pose.has_value());
  const Eigen::Matrix3d& read = entry.pose->R;
  CHECK((read.transpose() * read - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-14);
  CHECK(read.determinant() == doctest::Approx(1.0).epsilon(1e-14));
  CHECK((read - R).cwiseAbs().maxCoeff() < 1e-6);
  CHECK(entry.pose->t == Eigen::Vector3d(0, 0, 1));
}

TEST_CASE("malformed manifest lines name the line and the field") {
  const std::string R = "[[1,0,0],[0,1,0],[0,0,1]]";
  CHECK(ParseError("{\"R\":" + R + ",\"t\":[0,0,0]}") == "m.jsonl: line 4: cloud: missing (required)");
  CHECK(ParseError("{\"cloud\":3}") == "m.jsonl: line 4: cloud: expected a string");
  CHECK(ParseError("{\"cloud\":\"/etc/passwd\"}") ==
        "m.jsonl: line 4: cloud: absolute path '/etc/passwd' (must be relative to the dataset folder)");
  CHECK(ParseError("{\"cloud\":\"../other/a.ply\"}") == "m.jsonl: line 4: cloud: path '../other/a.ply' escapes the dataset folder");
  CHECK(ParseError("{\"cloud\":\"a/../../b.ply\"}") == "m.jsonl: line 4: cloud: path 'a/../../b.ply' escapes the dataset folder");
  CHECK(ParseError("{\"cloud\":\"a/..\"}") == "m.jsonl: line 4: cloud: path 'a/..' does not name a file");
  CHECK(c3po::ParseManifestLine("{\"cloud\":\"a/../b.ply\"}", "m").cloud == "a/../b.ply");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"R\":[[1,0,0],[0,1,0],[0,0,-1]],\"t\":[0,0,0]}") ==
        "m.jsonl: line 4: R: determinant is -1 (a reflection, not a rotation)");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"R\":[[1,0,0],[0,1,0],[0,0,1.001]],\"t\":[0,0,0]}").rfind(
            "m.jsonl: line 4: R: not orthonormal", 0) == 0);
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"R\":[[1,0,0],[0,1,0]],\"t\":[0,0,0]}") == "m.jsonl: line 4: R: expected 3 rows of 3 numbers");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"R\":[[1,0,0],[0,1,\"0\"],[0,0,1]],\"t\":[0,0,0]}") ==
        "m.jsonl: line 4: R: expected a number, found string");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"R\":" + R + "}") == "m.jsonl: line 4: t: missing (\"R\" and \"t\" go together)");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"R\":" + R + ",\"t\":[0,1e999,0]}") == "m.jsonl: line 4: not valid JSON: number overflow parsing '1e999'");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"keypoints\":[[0,0,0],[1,2]]}") ==
        "m.jsonl: line 4: keypoints: item 1: expected an array of 3 numbers");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"keypoints\":[]}") == "m.jsonl: line 4: keypoints: expected a non-empty array of [x, y, z]");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"keypoints\":[[0,0,0]],\"visible\":[true,false]}") ==
        "m.jsonl: line 4: visible: 2 entries, but keypoints has 1");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"keypoints\":[[0,0,0]],\"detected_keypoints\":[[0,0,0],[1,1,1]]}") ==
        "m.jsonl: line 4: detected_keypoints: 2 entries, but keypoints has 1");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"visible\":[1]}") == "m.jsonl: line 4: visible: expected booleans, found number");
  CHECK(ParseError("{\"cloud\":\"a.ply\"").rfind("m.jsonl: line 4: not valid JSON: ", 0) == 0);
  CHECK(ParseError("[1,2,3]") == "m.jsonl: line 4: expected a JSON object");
  CHECK(ParseError("{\"cloud\":\"../a\\nb.ply\"}") == "m.jsonl: line 4: cloud: path '../a?b.ply' escapes the dataset folder");
  CHECK(ParseError(std::string(100000, '[')) == "m.jsonl: line 4: JSON nested too deeply");
}

TEST_CASE("ReadDataset: missing folder or manifest, inconsistent lines, missing clouds") {
  c3po::test::TempDir dir("dataset_read");
  CHECK(InputErrorOf([&] { c3po::ReadDataset(dir / "absent"); }) == dir / "absent: no such folder");
  CHECK(InputErrorOf([&] { c3po::ReadDataset(dir.path() + "/"); }) == dir.path() + ": no manifest.jsonl (not a c3po dataset)");

  c3po::Rng rng(13);
  c3po::WritePly(dir / "a.ply", RandomPoints(rng, 10));
  c3po::WritePly(dir / "b.ply", RandomPoints(rng, 12));
  const std::string manifest = dir / "manifest.jsonl";
  const std::string a = c3po::ManifestLine(RandomEntry(rng, "a.ply", 4));
  c3po::WriteFileAtomically(manifest, "\n" + a + "\n\n" + c3po::ManifestLine(RandomEntry(rng, "b.ply", 5)) + "\n");
  CHECK(InputErrorOf([&] { c3po::ReadDataset(dir.path()); }) ==
        manifest + ": line 4: keypoints: 5 keypoints, but line 2 has 4");
  c3po::WriteFileAtomically(manifest, a + "\r\n{\"cloud\":\"c.ply\"}\n");
  CHECK(InputErrorOf([&] { c3po::ReadDataset(dir.path()); }) == manifest + ": line 2: cloud: no such file '" + dir / "c.ply'");
  c3po::WriteFileAtomically(manifest, "\n  \n");
  CHECK(InputErrorOf([&] { c3po::ReadDataset(dir.path()); }) == manifest + ": no entries");

  c3po::WriteFileAtomically(manifest, a + "\r\n{\"cloud\":\"b.ply\"}");   // CRLF, no final newline
  const c3po::Dataset dataset = c3po::ReadDataset(dir.path());
  REQUIRE(dataset.entries.size() == 2);
  CHECK(dataset.CloudPath(1) == dir / "b.ply");
  CHECK(dataset.LoadCloud(1).cols() == 12);
  CHECK_FALSE(dataset.HasGroundTruth());
}

TEST_CASE("DatasetWriter: parallel producers, sorted manifest, exact round trip") {
  c3po::test::TempDir dir("dataset_writer");
  const std::string target = dir / "out/ds";   // parent folder created on demand
  constexpr int kCount = 24;
  std::vector<c3po::DatasetEntry> entries;
  std::vector<c3po::PointSet> clouds;
  for (int i = 0; i < kCount; ++i) {
    c3po::Rng rng = c3po::Rng::ForItem(14, static_cast<std::uint64_t>(i));
    char name[32];
    std::snprintf(name, sizeof name, "%06d.ply", i);
    entries.push_back(RandomEntry(rng, i % 5 == 0 ? std::string("sub/") + name : name, 6));
    clouds.push_back(RandomPoints(rng, 50 + i));
  }
  {
    c3po::DatasetWriter writer(target);
    CHECK(fs::is_directory(writer.temporary_dir()));
    CHECK(fs::path(writer.temporary_dir()).filename().string().rfind(".ds.partial.", 0) == 0);
    // Two producers adding in reverse, interleaved order.
    const auto produce = [&](int parity) {
      for (int i = kCount - 1 - parity; i >= 0; i -= 2) writer.Add(static_cast<std::size_t>(i), entries[static_cast<std::size_t>(i)], clouds[static_cast<std::size_t>(i)]);
    };
    std::thread first(produce, 0), second(produce, 1);
    first.join();
    second.join();
    CHECK_FALSE(fs::exists(target));   // nothing visible before Commit
    writer.Commit();
  }
  CHECK(Listing(dir / "out") == std::vector<std::string>{"ds"});
  const c3po::Dataset dataset = c3po::ReadDataset(target);
  REQUIRE(dataset.entries.size() == kCount);
  CHECK(dataset.HasGroundTruth());
  for (int i = 0; i < kCount; ++i) {
    CAPTURE(i);
    CheckSame(dataset.entries[static_cast<std::size_t>(i)], entries[static_cast<std::size_t>(i)]);
    const c3po::PointSet read = dataset.LoadCloud(static_cast<std::size_t>(i));
    const c3po::PointSet& written = clouds[static_cast<std::size_t>(i)];
    REQUIRE(read.cols() == written.cols());
    for (Eigen::Index k = 0; k < written.size(); ++k) CHECK(read.data()[k] == static_cast<double>(static_cast<float>(written.data()[k])));
  }
}

TEST_CASE("DatasetWriter: abandoned writer leaves nothing, commit replaces an old dataset") {
  c3po::test::TempDir dir("dataset_replace");
  const std::string target = dir / "ds";
  c3po::Rng rng(15);
  c3po::DatasetEntry entry;
  entry.cloud = "0.ply";
  {
    c3po::DatasetWriter writer(target);
    writer.Add(0, entry, RandomPoints(rng, 5));
  }   // no Commit: as if interrupted
  CHECK(fs::is_empty(dir.path()));

  // A writer killed outright (no destructor) leaves its partial folder; the
  // next writer removes it when that process is gone, and keeps live ones.
  int pipe_fds[2];
  REQUIRE(::pipe(pipe_fds) == 0);
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {   // idle until the pipe closes, then exit without cleanup
    ::close(pipe_fds[1]);
    char byte;
    while (::read(pipe_fds[0], &byte, 1) > 0) {}
    ::_exit(0);
  }
  ::close(pipe_fds[0]);
  const std::string dead = dir / ".ds.partial.999999999";   // beyond pid_max: no such process
  const std::string alive = dir / ".ds.partial." + std::to_string(child);
  fs::create_directory(dead);
  fs::create_directory(alive);
  {
    c3po::DatasetWriter writer(target);
  }
  CHECK_FALSE(fs::exists(dead));
  CHECK(fs::exists(alive));
  ::close(pipe_fds[1]);
  ::waitpid(child, nullptr, 0);
  fs::remove_all(alive);

  {
    c3po::DatasetWriter writer(target);
    c3po::DatasetEntry old_entry;
    old_entry.cloud = "old_only.ply";
    writer.Add(0, old_entry, RandomPoints(rng, 5));
    writer.Commit();
  }
  CHECK(fs::exists(target + "/old_only.ply"));
  {
    c3po::DatasetWriter writer(target);
    writer.Add(0, entry, RandomPoints(rng, 7));
    CHECK(fs::exists(target + "/old_only.ply"));   // old dataset intact until Commit
    writer.Commit();
  }
  CHECK(Listing(dir.path()) == std::vector<std::string>{"ds"});
  CHECK(Listing(target) == std::vector<std::string>{"0.ply", "manifest.jsonl"});
  CHECK(c3po::ReadDataset(target).LoadCloud(0).cols() == 7);

  // An empty folder is also a fine target.
  fs::create_directory(dir / "empty");
  {
    c3po::DatasetWriter writer(dir / "empty");
    writer.Add(0, entry, RandomPoints(rng, 3));
    writer.Commit();
  }
  CHECK(c3po::ReadDataset(dir / "empty").entries.size() == 1);
}

TEST_CASE("DatasetWriter refuses to overwrite a folder that is not a dataset") {
  c3po::test::TempDir dir("dataset_refuse");
  fs::create_directory(dir / "photos");
  c3po::WriteFileAtomically(dir / "photos/holiday.jpg", std::string("jpeg"));
  const std::string refusal = dir / "photos: exists and is not a c3po dataset (no manifest.jsonl); refusing to overwrite it";
  CHECK(InputErrorOf([&] { c3po::DatasetWriter writer(dir / "photos"); }) == refusal);
  c3po::WriteFileAtomically(dir / "notes.txt", std::string("text"));
  CHECK(InputErrorOf([&] { c3po::DatasetWriter writer(dir / "notes.txt"); }).rfind(dir / "notes.txt: exists", 0) == 0);

  // The folder appears while the writer works: Commit refuses, nothing is touched.
  c3po::Rng rng(16);
  c3po::DatasetEntry entry;
  entry.cloud = "0.ply";
  {
    c3po::DatasetWriter writer(dir / "late");
    writer.Add(0, entry, RandomPoints(rng, 3));
    fs::create_directory(dir / "late");
    c3po::WriteFileAtomically(dir / "late/precious.txt", std::string("keep"));
    CHECK(InputErrorOf([&] { writer.Commit(); }) ==
          dir / "late: exists and is not a c3po dataset (no manifest.jsonl); refusing to overwrite it");
  }
  CHECK(Listing(dir / "late") == std::vector<std::string>{"precious.txt"});
  CHECK(Listing(dir.path()) == std::vector<std::string>{"late", "notes.txt", "photos"});
}

TEST_CASE("DatasetWriter into an unwritable place gives InputError and no output") {
  // A path under a regular file fails with ENOTDIR even for root (who can
  // write into read-only folders, so a chmod-based test would not fail).
  c3po::test::TempDir dir("dataset_unwritable");
  c3po::WriteFileAtomically(dir / "file", std::string("x"));
  const std::string message = InputErrorOf([&] { c3po::DatasetWriter writer(dir / "file/ds"); });
  CHECK(message.rfind(dir / "file/ds: cannot write: ", 0) == 0);
  CHECK(Listing(dir.path()) == std::vector<std::string>{"file"});
  MESSAGE("unwritable folder simulated with a path under a regular file: " << message);
}

TEST_CASE("float32 / few-digit rotations (within 1e-4) are projected, certify-style reading skips ground truth") {
  c3po::Rng rng(31);
  const Eigen::Matrix3d R = rng.Rotation();
  std::string rows;
  for (int r = 0; r < 3; ++r) {
    char buffer[128];
    std::snprintf(buffer, sizeof buffer, "[%.5f,%.5f,%.5f]", R(r, 0), R(r, 1), R(r, 2));   // ~1e-5 off
    rows += (r ? "," : "") + std::string(buffer);
  }
  const auto entry = c3po::ParseManifestLine("{\"cloud\":\"a.ply\",\"R\":[" + rows + "],\"t\":[0,0,1]}", "m");
  REQUIRE(entry.pose.has_value());
  CHECK((entry.pose->R.transpose() * entry.pose->R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-14);
  CHECK((entry.pose->R - R).cwiseAbs().maxCoeff() < 2e-5);
  // Clearly not a rotation: refused with the measured error, unless ground truth is not read.
  const std::string bad = "{\"cloud\":\"a.ply\",\"R\":[[1,0,0],[0,1,0],[0,0,1.001]],\"t\":[0,0,0],\"keypoints\":[[0,0,0]]}";
  CHECK(ParseError(bad) == "m.jsonl: line 4: R: not orthonormal (max |R^T R - I| = 0.002, tolerance 0.0001)");
  const auto skipped = c3po::ParseManifestLine(bad, "m", /*ground_truth=*/false);
  CHECK(!skipped.pose);
  CHECK(!skipped.keypoints);
  CHECK(skipped.cloud == "a.ply");
}

TEST_CASE("object labels: round trip, validation, keypoint counts agree per object only") {
  c3po::Rng rng(21);
  c3po::DatasetEntry entry = RandomEntry(rng, "a.ply", 4);
  entry.object = "035 power drill (YCB)";
  const std::string line = c3po::ManifestLine(entry);
  CHECK(line.find("\"object\":\"035 power drill (YCB)\"") != std::string::npos);
  CheckSame(c3po::ParseManifestLine(line, "m"), entry);
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"object\":5}") ==
        "m.jsonl: line 4: object: expected a string (the object's name)");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"object\":\"\"}") == "m.jsonl: line 4: object: expected 1 to 256 characters");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"object\":\"" + std::string(257, 'x') + "\"}") ==
        "m.jsonl: line 4: object: expected 1 to 256 characters");
  CHECK(ParseError("{\"cloud\":\"a.ply\",\"object\":\"a\\nb\"}") == "m.jsonl: line 4: object: control character in 'a?b'");
  entry.object = "";
  CHECK_THROWS_AS(c3po::ManifestLine(entry), std::invalid_argument);
  entry.object = std::string("a\tb");
  CHECK_THROWS_AS(c3po::ManifestLine(entry), std::invalid_argument);

  // Different objects may have different keypoint counts; the same object may not.
  c3po::test::TempDir dir("dataset_labels");
  c3po::WritePly(dir / "a.ply", RandomPoints(rng, 10));
  c3po::WritePly(dir / "b.ply", RandomPoints(rng, 12));
  c3po::WritePly(dir / "c.ply", RandomPoints(rng, 12));
  c3po::DatasetEntry a = RandomEntry(rng, "a.ply", 4), b = RandomEntry(rng, "b.ply", 5), c = RandomEntry(rng, "c.ply", 6);
  a.object = "drill";
  b.object = "mug";
  c.object = "drill";
  const std::string manifest = dir / "manifest.jsonl";
  c3po::WriteFileAtomically(manifest, c3po::ManifestLine(a) + "\n" + c3po::ManifestLine(b) + "\n");
  const c3po::Dataset mixed = c3po::ReadDataset(dir.path());
  REQUIRE(mixed.entries.size() == 2);
  CHECK(mixed.Shows(0, "drill"));
  CHECK_FALSE(mixed.Shows(1, "drill"));
  CHECK(mixed.Shows(1, "mug"));
  c3po::WriteFileAtomically(manifest, c3po::ManifestLine(a) + "\n" + c3po::ManifestLine(b) + "\n" +
                                          c3po::ManifestLine(c) + "\n");
  CHECK(InputErrorOf([&] { c3po::ReadDataset(dir.path()); }) ==
        manifest + ": line 3: keypoints: 6 keypoints, but line 1 has 4 (object drill)");
  // An unlabelled line shows every object.
  c3po::DatasetEntry bare;
  bare.cloud = "a.ply";
  c3po::WriteFileAtomically(manifest, c3po::ManifestLine(bare) + "\n");
  CHECK(c3po::ReadDataset(dir.path()).Shows(0, "anything"));
}

TEST_CASE("MergeDatasets --prefix-parts joins datasets with the same cloud names, labels kept") {
  c3po::test::TempDir dir("dataset_merge_prefix");
  c3po::Rng rng(22);
  std::vector<c3po::PointSet> clouds;
  for (const std::string part : {"drill", "mug"}) {
    c3po::DatasetWriter writer(dir / part);
    for (int i = 0; i < 3; ++i) {
      c3po::DatasetEntry entry = RandomEntry(rng, "00000" + std::to_string(i) + ".ply", part == "drill" ? 4 : 7);
      entry.object = part;
      clouds.push_back(RandomPoints(rng, 5 + i));
      writer.Add(static_cast<std::size_t>(i), entry, clouds.back());
    }
    writer.Commit();
  }
  // Without the prefix the names collide.
  CHECK(InputErrorOf([&] { c3po::MergeDatasets({dir / "drill", dir / "mug"}, dir / "plain"); }).find(
            "is also in an earlier part") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "plain"));
  CHECK(c3po::MergeDatasets({dir / "drill", dir / "mug/"}, dir / "mixed", true) == 6);
  const c3po::Dataset mixed = c3po::ReadDataset(dir / "mixed");
  REQUIRE(mixed.entries.size() == 6);
  for (std::size_t i = 0; i < 6; ++i) {
    const std::string part = i < 3 ? "drill" : "mug";
    CHECK(mixed.entries[i].cloud == part + "/00000" + std::to_string(i % 3) + ".ply");
    CHECK(mixed.entries[i].object == part);
    CHECK(mixed.LoadCloud(i).isApprox(clouds[i], 1e-6));
  }
  // Two parts with the same folder name still collide.
  CHECK(InputErrorOf([&] { c3po::MergeDatasets({dir / "drill", dir / "drill"}, dir / "twice", true); }).find(
            "two parts with the same folder name") != std::string::npos);
}
