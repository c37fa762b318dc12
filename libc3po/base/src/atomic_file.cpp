// Atomic file output: write to a unique temporary sibling, check, fsync, rename.
#include "c3po/base/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
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

}  // namespace c3po
