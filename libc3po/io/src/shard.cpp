#include "c3po/io/shard.hpp"

#include <nlohmann/json.hpp>

#include "c3po/base/lines.hpp"
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

std::int64_t ImageGroupKey(int scene_id, int im_id) {
  return static_cast<std::int64_t>(scene_id) * 1000000000LL + im_id;
}

Dataset ShardDataset(const Dataset& dataset, const Shard& shard) {
  std::vector<std::int64_t> keys(dataset.entries.size());
  for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = static_cast<std::int64_t>(i);
  Dataset part;
  part.dir = dataset.dir;
  for (std::size_t i : ShardJobs(keys, shard)) part.entries.push_back(dataset.entries[i]);
  return part;
}

std::string MergeShardOutputs(const std::vector<std::pair<std::string, std::string>>& parts, bool csv) {
  std::string merged, header;
  for (const auto& [name, text] : parts) {
    std::size_t line_number = 0;
    for (const std::string_view view : SplitLines(text)) {
      const std::string line(view);
      ++line_number;
      if (csv && line_number == 1) {
        if (line.rfind("scene_id,im_id,obj_id,score,R,t,time", 0) != 0) throw InputError(name, "line 1: not a BOP results CSV header");
        if (header.empty()) {
          header = line;
          merged += line + "\n";
        } else if (line != header) {
          throw InputError(name, "line 1: header differs from the first part's");
        }
        continue;
      }
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      if (!csv) {
        const nlohmann::json parsed = nlohmann::json::parse(line, nullptr, false);
        if (!parsed.is_object()) throw InputError(name, "line " + std::to_string(line_number) + ": not a JSON object");
      }
      merged += line + "\n";
    }
    if (csv && line_number == 0) throw InputError(name, "empty (a BOP CSV part has at least its header)");
  }
  return merged;
}

}  // namespace c3po
