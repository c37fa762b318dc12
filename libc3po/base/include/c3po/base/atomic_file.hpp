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

// Reads a whole file; throws InputError("path: cannot read: reason").
std::string ReadFileToString(const std::string& path);

}  // namespace c3po
