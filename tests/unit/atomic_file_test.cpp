// WriteFileAtomically / ReadFileToString: complete files or nothing, old
// contents survive failures, no temporary files are left behind.
#include <doctest/doctest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "test_helpers.hpp"

using c3po::test::InputErrorOf;

namespace {

std::vector<std::string> Listing(const std::string& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST_CASE("writes, replaces and reads back, leaving only the destination") {
  c3po::test::TempDir dir("atomic_write");
  std::string contents;
  for (unsigned i = 0; i < 300000; ++i) contents += static_cast<char>(i * 7919u % 256u);   // > stream buffer
  c3po::WriteFileAtomically(dir / "data.bin", contents);
  CHECK(c3po::ReadFileToString(dir / "data.bin") == contents);
  c3po::WriteFileAtomically(dir / "data.bin", [](std::ostream& out) { out << "replaced\n"; });
  CHECK(c3po::ReadFileToString(dir / "data.bin") == "replaced\n");
  c3po::WriteFileAtomically(dir / "empty", std::string());
  CHECK(c3po::ReadFileToString(dir / "empty").empty());
  CHECK(Listing(dir.path()) == std::vector<std::string>{"data.bin", "empty"});
}

TEST_CASE("a failing writer leaves the old file intact and no temporary") {
  c3po::test::TempDir dir("atomic_failure");
  c3po::WriteFileAtomically(dir / "keep.txt", std::string("old contents"));
  CHECK_THROWS_AS(c3po::WriteFileAtomically(dir / "keep.txt",
                                            [](std::ostream& out) {
                                              out << "half of the new contents";
                                              throw std::runtime_error("interrupted");
                                            }),
                  std::runtime_error);
  CHECK(c3po::ReadFileToString(dir / "keep.txt") == "old contents");
  // A stream put into a failed state also aborts the write.
  const std::string message = InputErrorOf([&] {
    c3po::WriteFileAtomically(dir / "keep.txt", [](std::ostream& out) {
      out << "x";
      out.setstate(std::ios::badbit);
    });
  });
  CHECK(message == dir / "keep.txt: cannot write: Input/output error");
  CHECK(c3po::ReadFileToString(dir / "keep.txt") == "old contents");
  CHECK(Listing(dir.path()) == std::vector<std::string>{"keep.txt"});
}

TEST_CASE("an unwritable destination gives InputError and no output") {
  c3po::test::TempDir dir("atomic_unwritable");
  c3po::WriteFileAtomically(dir / "file", std::string("a regular file"));
  // A path under a regular file fails with ENOTDIR for every user, root included.
  CHECK(InputErrorOf([&] { c3po::WriteFileAtomically(dir / "file/out.txt", std::string("x")); }) ==
        dir / "file/out.txt: cannot write: Not a directory");
  CHECK(InputErrorOf([&] { c3po::WriteFileAtomically(dir / "missing/out.txt", std::string("x")); }) ==
        dir / "missing/out.txt: cannot write: No such file or directory");
  // The destination is a folder: the rename fails, the temporary is removed.
  std::filesystem::create_directory(dir / "folder");
  CHECK(InputErrorOf([&] { c3po::WriteFileAtomically(dir / "folder", std::string("x")); }) ==
        dir / "folder: cannot write: Is a directory");
  CHECK(Listing(dir.path()) == std::vector<std::string>{"file", "folder"});
  // A read-only folder only stops users other than root (root bypasses modes).
  std::filesystem::create_directory(dir / "readonly");
  std::filesystem::permissions(dir / "readonly", std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  if (::geteuid() != 0) {
    CHECK(InputErrorOf([&] { c3po::WriteFileAtomically(dir / "readonly/out.txt", std::string("x")); }) ==
          dir / "readonly/out.txt: cannot write: Permission denied");
  } else {
    MESSAGE("running as root: the read-only folder case is covered by the ENOTDIR case above");
  }
  std::filesystem::permissions(dir / "readonly", std::filesystem::perms::owner_all);
  CHECK(std::filesystem::is_empty(dir / "readonly"));
}

TEST_CASE("CheckWritableFile fails exactly where WriteFileAtomically fails, and creates nothing") {
  c3po::test::TempDir dir("atomic_check");
  c3po::WriteFileAtomically(dir / "file", std::string("a regular file"));
  std::filesystem::create_directory(dir / "folder");
  std::filesystem::create_directory(dir / "readonly");
  std::filesystem::permissions(dir / "readonly", std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
  const std::vector<std::string> before = Listing(dir.path());
  const std::vector<std::string> paths = {dir / "new.txt", dir / "file", dir / "file/out.txt", dir / "missing/out.txt",
                                          dir / "folder", dir / "folder/", dir / "readonly/out.txt", ""};
  for (const std::string& path : paths) {
    CAPTURE(path);
    const bool existed = std::filesystem::exists(path);
    const std::string checked = InputErrorOf([&] { c3po::CheckWritableFile(path); });
    CHECK(Listing(dir.path()) == before);   // the check leaves nothing
    CHECK(std::filesystem::is_empty(dir / "readonly"));
    // The oracle: what the write itself says (a read-only folder stops it
    // only for users other than root, and the check agrees either way).
    const std::string written = InputErrorOf([&] { c3po::WriteFileAtomically(path, std::string("x")); });
    CHECK(checked == written);
    if (written.empty() && !existed) std::filesystem::remove(path);
  }
  CHECK(InputErrorOf([&] { c3po::CheckWritableFile(dir / "missing/out.txt"); }) ==
        dir / "missing/out.txt: cannot write: No such file or directory");
  std::filesystem::permissions(dir / "readonly", std::filesystem::perms::owner_all);
}

TEST_CASE("ReadFileToString errors name the file") {
  c3po::test::TempDir dir("atomic_read");
  CHECK(InputErrorOf([&] { c3po::ReadFileToString(dir / "none"); }) == dir / "none: cannot read: No such file or directory");
  CHECK(InputErrorOf([&] { c3po::ReadFileToString(dir.path()); }) == dir.path() + ": cannot read: Is a directory");
}
