#pragma once
// --shard K/N (issue 15): the K-th (1-based) of N disjoint, deterministic
// parts of a job list, so that many machines (GNU parallel, a Slurm job
// array) share a run. Jobs are grouped (a BOP image's instances stay
// together; a manifest line or cloud is its own group) and each part is a
// contiguous block of groups: parts 1..N, concatenated in order, are exactly
// the unsharded job list, so merging outputs is concatenation (`c3po merge`).
#include <cstdint>
#include <string>
#include <vector>

#include "c3po/io/dataset.hpp"

namespace c3po {

struct Shard {
  int index = 1;   // K, 1-based
  int count = 1;   // N
  bool all() const { return count == 1; }
};

// "K/N" with 1 <= K <= N; throws InputError("--shard", ...).
Shard ParseShard(const std::string& text);

// Indices of the jobs in `shard`, given each job's group key in job order
// (jobs of one group adjacent). Groups g = 0..G-1 in order of appearance; the
// shard takes groups [floor((K-1) G / N), floor(K G / N)).
std::vector<std::size_t> ShardJobs(const std::vector<std::int64_t>& group_keys, const Shard& shard);

// The group key of a BOP image (its instances form one group).
std::int64_t ImageGroupKey(int scene_id, int im_id);

// The K-th part of a dataset, by manifest line (eval --shard on --data).
Dataset ShardDataset(const Dataset& dataset, const Shard& shard);

// Joins shard outputs given in shard order (name, contents): JSON lines are
// concatenated (every non-empty line must be a JSON object); BOP CSVs
// (`csv`) keep one header, which every part must have. Throws InputError
// naming the part.
std::string MergeShardOutputs(const std::vector<std::pair<std::string, std::string>>& parts, bool csv);

}  // namespace c3po
