#pragma once
// Atomic outputs: everything is written to a temporary file in the destination
// folder and renamed over the destination only when complete, so an
// interrupted or failing run never leaves a partial file and never damages an
// existing one.
#include <functional>
#include <ostream>
#include <string>

namespace c3po {

// Calls `write` on a binary stream to a temporary sibling of `path`, checks the
// stream, flushes to disk (fsync) and renames. Throws InputError("path: cannot
// write: reason") on failure (the temporary file is removed). `sync = false`
// skips the fsync, for files inside a folder that is itself published
// atomically and synced once (DatasetWriter).
void WriteFileAtomically(const std::string& path,
                         const std::function<void(std::ostream&)>& write, bool sync = true);
void WriteFileAtomically(const std::string& path, const std::string& contents);

// Throws WriteFileAtomically's InputError("path: cannot write: reason") now
// if it would fail later for want of a place: `path` is no file name or is a
// folder, or its folder is missing or takes no new file (tried by creating and
// removing the temporary sibling; nothing is left). For commands to call
// before long work, so that a typo in an output path does not cost the run.
void CheckWritableFile(const std::string& path);

// A folder published atomically: files are written into a hidden sibling
// ".<name>.partial.<pid>" (path()), and Commit() syncs it once and renames it
// to `dir`. An existing `dir` is replaced only when it is empty or holds the
// `marker` file (a folder this kind of writer made); anything else is refused
// with InputError("dir: exists and is not a <kind> (no <marker>); refusing to
// overwrite it"), checked by the constructor too so a long run fails before
// it starts. Destroying an uncommitted StagedFolder removes the partial
// folder, so an interrupted run leaves nothing; partial folders of killed
// processes are removed by the next writer of the same `dir`.
class StagedFolder {
 public:
  StagedFolder(std::string dir, std::string marker, std::string kind);
  ~StagedFolder();
  StagedFolder(const StagedFolder&) = delete;
  StagedFolder& operator=(const StagedFolder&) = delete;

  const std::string& dir() const { return dir_; }
  const std::string& path() const { return tmp_dir_; }   // where to write
  // Files written without fsync are made durable here (one syncfs).
  void Commit();
  bool committed() const { return committed_; }

 private:
  void CheckReplaceable() const;
  bool HasMarker() const;

  std::string dir_;
  std::string marker_;
  std::string kind_;
  std::string tmp_dir_;
  bool committed_ = false;
};

// Reads a whole file; throws InputError("path: cannot read: reason").
std::string ReadFileToString(const std::string& path);

}  // namespace c3po
