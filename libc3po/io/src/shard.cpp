#include "c3po/io/shard.hpp"

#include "c3po/base/error.hpp"

namespace c3po {

Shard ParseShard(const std::string& text) {
  const std::size_t slash = text.find('/');
  auto number = [&](const std::string& part) {
    if (part.empty() || part.size() > 6 || part.find_first_not_of("0123456789") != std::string::npos) {
      throw InputError("--shard", "'" + text + "' is not K/N (e.g. 3/8)");
    }
    return std::stoi(part);
  };
  if (slash == std::string::npos) throw InputError("--shard", "'" + text + "' is not K/N (e.g. 3/8)");
  Shard shard{number(text.substr(0, slash)), number(text.substr(slash + 1))};
  if (shard.count < 1 || shard.index < 1 || shard.index > shard.count) {
    throw InputError("--shard", "'" + text + "': need 1 <= K <= N");
  }
  return shard;
}

std::vector<std::size_t> ShardJobs(const std::vector<std::int64_t>& group_keys, const Shard& shard) {
  // Group number of each job.
  std::vector<std::size_t> group(group_keys.size());
  std::size_t groups = 0;
  for (std::size_t i = 0; i < group_keys.size(); ++i) {
    if (i > 0 && group_keys[i] != group_keys[i - 1]) ++groups;
    group[i] = groups;
  }
  if (!group_keys.empty()) ++groups;
  const std::size_t first = static_cast<std::size_t>(shard.index - 1) * groups / static_cast<std::size_t>(shard.count);
  const std::size_t last = static_cast<std::size_t>(shard.index) * groups / static_cast<std::size_t>(shard.count);
  std::vector<std::size_t> jobs;
  for (std::size_t i = 0; i < group.size(); ++i) {
    if (group[i] >= first && group[i] < last) jobs.push_back(i);
  }
  return jobs;
}

}  // namespace c3po
