// Atomic file output: write to a unique temporary sibling, check, fsync, rename.
#include "c3po/base/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <streambuf>
#include <vector>

#include "c3po/base/error.hpp"
#include "c3po/base/paths.hpp"

namespace c3po {
namespace {

std::string ErrnoText(int error) { return std::strerror(error); }

// A minimal output stream buffer over a POSIX file descriptor that remembers
// the first errno, so failures can be reported precisely (std::ofstream hides
// them).
class FdStreamBuf : public std::streambuf {
 public:
  explicit FdStreamBuf(int fd) : fd_(fd), buffer_(1 << 16) {
    setp(buffer_.data(), buffer_.data() + buffer_.size());
  }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type ch) override {
    if (!Drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  int sync() override { return Drain() ? 0 : -1; }

 private:
  bool Drain() {
    const char* data = pbase();
    std::size_t left = static_cast<std::size_t>(pptr() - pbase());
    while (left > 0) {
      const ssize_t n = ::write(fd_, data, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        if (error_ == 0) error_ = errno;
        return false;
      }
      data += n;
      left -= static_cast<std::size_t>(n);
    }
    setp(buffer_.data(), buffer_.data() + buffer_.size());
    return true;
  }

  int fd_;
  std::vector<char> buffer_;
  int error_ = 0;
};

// ".name.tmp.<pid>.<counter>" next to `path`.
std::string TemporarySibling(const std::string& path) {
  static std::atomic<unsigned long> counter{0};
  const std::string parent = ParentOf(path);
  return (parent == "/" ? "" : parent) + "/." + LeafOf(path) + ".tmp." +
         std::to_string(::getpid()) + "." + std::to_string(counter++);
}

void SyncFolder(const std::string& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;   // best effort: the rename itself already happened
  ::fsync(fd);
  ::close(fd);
}

[[noreturn]] void Fail(const std::string& path, int error) {
  throw InputError(path, "cannot write: " + ErrnoText(error));
}

// Writes through `write`, returns 0 or the errno of the first failure.
int WriteAndSync(int fd, const std::function<void(std::ostream&)>& write, bool sync) {
  FdStreamBuf buffer(fd);
  std::ostream stream(&buffer);
  write(stream);
  stream.flush();
  if (buffer.error() != 0) return buffer.error();
  if (!stream) return EIO;
  if (sync && ::fsync(fd) != 0) return errno;
  return 0;
}

}  // namespace

void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write, bool sync) {
  if (path.empty() || path.back() == '/') throw InputError(path, "cannot write: not a file name");
  const std::string temporary = TemporarySibling(path);
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) Fail(path, errno);
  int error = 0;
  try {
    error = WriteAndSync(fd, write, sync);
  } catch (...) {
    ::close(fd);
    ::unlink(temporary.c_str());
    throw;
  }
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error == 0 && ::rename(temporary.c_str(), path.c_str()) != 0) error = errno;
  if (error != 0) {
    ::unlink(temporary.c_str());
    Fail(path, error);
  }
  if (sync) SyncFolder(ParentOf(path));
}

void CheckWritableFile(const std::string& path) {
  if (path.empty() || path.back() == '/') throw InputError(path, "cannot write: not a file name");
  struct stat status {};
  if (::stat(path.c_str(), &status) == 0 && S_ISDIR(status.st_mode)) Fail(path, EISDIR);
  const std::string temporary = TemporarySibling(path);
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) Fail(path, errno);
  ::close(fd);
  ::unlink(temporary.c_str());
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  WriteFileAtomically(path, [&contents](std::ostream& out) {
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
  });
}

std::string ReadFileToString(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(path, "cannot read: " + ErrnoText(errno));
  struct stat info {};
  if (::fstat(fd, &info) != 0 || S_ISDIR(info.st_mode)) {
    const int error = S_ISDIR(info.st_mode) ? EISDIR : errno;
    ::close(fd);
    throw InputError(path, "cannot read: " + ErrnoText(error));
  }
  std::string contents;
  if (S_ISREG(info.st_mode) && info.st_size > 0) contents.reserve(static_cast<std::size_t>(info.st_size));
  char chunk[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, chunk, sizeof chunk);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      ::close(fd);
      throw InputError(path, "cannot read: " + ErrnoText(error));
    }
    contents.append(chunk, static_cast<std::size_t>(n));
  }
  ::close(fd);
  return contents;
}

namespace {

namespace fs = std::filesystem;

// Flushes every file of the folder's file system to disk (one syncfs instead
// of an fsync per file) and records the folder entries.
void SyncFileSystemOf(const std::string& folder) {
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::syncfs(fd);
  ::fsync(fd);
  ::close(fd);
}

// Removes ".<name>.partial.<pid>" siblings left by writers that were killed
// (their process no longer exists); live writers' folders are kept.
void RemoveStalePartials(const std::string& parent, const std::string& name) {
  const std::string prefix = "." + name + ".partial.";
  std::error_code ec;
  for (fs::directory_iterator it(parent, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string leaf = it->path().filename().string();
    if (leaf.rfind(prefix, 0) != 0) continue;
    const std::string pid_text = leaf.substr(prefix.size());
    if (pid_text.empty() || pid_text.find_first_not_of("0123456789") != std::string::npos || pid_text.size() > 9) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(pid_text));
    if (pid > 0 && ::kill(pid, 0) != 0 && errno == ESRCH) {
      std::error_code ignored;
      fs::remove_all(it->path(), ignored);
    }
  }
}

[[noreturn]] void FailWrite(const std::string& path, const std::error_code& ec) {
  throw InputError(path, "cannot write: " + ec.message());
}

}  // namespace

StagedFolder::StagedFolder(std::string dir, std::string marker, std::string kind)
    : dir_(StripTrailingSlashes(std::move(dir))), marker_(std::move(marker)), kind_(std::move(kind)) {
  const std::string name = fs::path(dir_).filename().string();
  if (dir_.empty() || name.empty() || name == "." || name == "..") {
    throw InputError(dir_, "cannot write: not a usable folder name");
  }
  CheckReplaceable();
  const fs::path parent_path = fs::path(dir_).parent_path();
  const std::string parent = parent_path.empty() ? "." : parent_path.string();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) FailWrite(dir_, ec);
  RemoveStalePartials(parent, name);
  tmp_dir_ = parent + "/." + name + ".partial." + std::to_string(::getpid());
  fs::remove_all(tmp_dir_, ec);
  if (!fs::create_directory(tmp_dir_, ec) || ec) {
    FailWrite(dir_, ec ? ec : std::make_error_code(std::errc::file_exists));
  }
}

StagedFolder::~StagedFolder() {
  if (committed_) return;
  std::error_code ec;
  fs::remove_all(tmp_dir_, ec);
}

bool StagedFolder::HasMarker() const {
  std::error_code ec;
  return fs::is_regular_file(fs::path(dir_) / marker_, ec);
}

void StagedFolder::CheckReplaceable() const {
  std::error_code ec;
  const fs::file_status status = fs::status(dir_, ec);
  if (!fs::exists(status)) return;
  if (fs::is_directory(status) && (HasMarker() || fs::is_empty(dir_, ec))) return;
  throw InputError(dir_, "exists and is not a " + kind_ + " (no " + marker_ +
                             "); refusing to overwrite it");
}

void StagedFolder::Commit() {
  if (committed_) throw std::logic_error("StagedFolder::Commit called twice");
  SyncFileSystemOf(tmp_dir_);
  CheckReplaceable();
  const fs::path parent_path = fs::path(dir_).parent_path();
  const std::string parent = parent_path.empty() ? "." : parent_path.string();
  std::error_code ec;
  if (HasMarker()) {
    // Swap: old folder away, new one in, old one deleted.
    const std::string old_dir =
        parent + "/." + fs::path(dir_).filename().string() + ".old." + std::to_string(::getpid());
    fs::remove_all(old_dir, ec);
    fs::rename(dir_, old_dir, ec);
    if (ec) FailWrite(dir_, ec);
    fs::rename(tmp_dir_, dir_, ec);
    if (ec) {
      std::error_code restore;
      fs::rename(old_dir, dir_, restore);
      FailWrite(dir_, ec);
    }
    fs::remove_all(old_dir, ec);
  } else {
    fs::rename(tmp_dir_, dir_, ec);   // also replaces an empty folder
    if (ec) FailWrite(dir_, ec);
  }
  SyncFileSystemOf(parent);   // make the renames durable
  committed_ = true;
}

}  // namespace c3po
