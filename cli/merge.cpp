// c3po merge: joins the outputs of `--shard K/N` runs, given in shard order,
// into what the unsharded run writes (JSON lines, or a BOP CSV by extension;
// with --eval, eval --samples parts into the unsharded eval table and JSON).
#include <cstdio>
#include <iostream>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "c3po/base/atomic_file.hpp"
#include "c3po/io/dataset.hpp"
#include "c3po/io/dataset_writer.hpp"
#include "c3po/base/error.hpp"
#include "c3po/eval/evaluation_samples.hpp"
#include "c3po/io/shard.hpp"
#include "command.hpp"

namespace c3po::cli {
namespace {

struct MergeCommand {
  std::vector<std::string> parts;
  std::string output_path;
  bool eval = false;   // --eval: eval --samples parts -> the table (+ -o: eval's --json document)
  bool prefix_parts = false;
};

int RunEval(const MergeCommand& cmd) {
  std::vector<std::pair<std::string, std::string>> parts;
  for (const std::string& path : cmd.parts) parts.emplace_back(path, ReadFileToString(path));
  const Evaluation evaluation = MergeEvaluationSamples(parts);
  if (!cmd.output_path.empty()) WriteFileAtomically(cmd.output_path, EvaluationJson(evaluation));
  std::cout << EvaluationTable(evaluation);
  return 0;
}

bool IsCsv(const std::string& path) { return path.size() >= 4 && path.compare(path.size() - 4, 4, ".csv") == 0; }

int Run(const MergeCommand& cmd) {
  if (cmd.eval) return RunEval(cmd);
  if (cmd.output_path.empty()) throw InputError("-o FILE is required (except with --eval)");
  std::error_code ec;
  if (std::filesystem::is_directory(cmd.parts.front(), ec)) {   // dataset folders (synth --shard)
    const std::size_t clouds = MergeDatasets(cmd.parts, cmd.output_path, cmd.prefix_parts);
    std::printf("wrote %s: %zu clouds from %zu parts\n", cmd.output_path.c_str(), clouds, cmd.parts.size());
    return 0;
  }
  const bool csv = IsCsv(cmd.output_path);
  std::vector<std::pair<std::string, std::string>> parts;
  for (const std::string& path : cmd.parts) {
    if (IsCsv(path) != csv) throw InputError(path, csv ? "not a .csv part for a .csv output" : "a .csv part for a JSON-lines output");
    parts.emplace_back(path, ReadFileToString(path));
    if (!csv && IsEvaluationSamples(parts.back().second)) {
      throw InputError(path, "eval samples (eval --samples): join them with c3po merge --eval");
    }
  }
  WriteFileAtomically(cmd.output_path, MergeShardOutputs(parts, csv));
  return 0;
}

}  // namespace

RunFunction SetupMerge(CLI::App& command) {
  auto cmd = std::make_shared<MergeCommand>();
  command.add_option("parts", cmd->parts, "Outputs of --shard 1/N .. N/N, in that order (files, or synth's dataset folders)")->required();
  command.add_option("-o,--output", cmd->output_path,
                     "Merged file (.csv: BOP CSV, one header; else JSON lines) or dataset folder; with --eval: "
                     "eval's --json document (optional)");
  command.add_flag("--eval", cmd->eval,
                   "Parts are eval --samples files of --shard 1/N .. N/N: print the unsharded eval table");
  command.add_flag("--prefix-parts", cmd->prefix_parts,
                   "Datasets: put each part's clouds under a folder named after the part (joins datasets with the "
                   "same cloud names, e.g. several objects' clouds into a mixed dataset)");
  command.footer("Example:\n  parallel c3po certify obj.json --bop DIR --obj-id 5 --detector svd -o part{}.jsonl --bop-csv part{}.csv "
                 "--shard {}/4 ::: 1 2 3 4\n  c3po merge -o poses.jsonl part{1..4}.jsonl && c3po merge -o results.csv part{1..4}.csv\n"
                 "  c3po synth obj.json -o sim_{} --kind sim --count 1000 --shard {}/4 ...; c3po merge -o sim sim_1 sim_2 sim_3 sim_4\n"
                 "  parallel c3po eval obj.json --data sim --detector svd --samples s{}.jsonl --shard {}/4 ::: 1 2 3 4\n"
                 "  c3po merge --eval s1.jsonl s2.jsonl s3.jsonl s4.jsonl -o eval.json\n"
                 "  c3po merge --prefix-parts -o mixed drill_depth mug_depth   # a mixed dataset (manifest \"object\" labels)");
  return [cmd]() { return Run(*cmd); };
}

}  // namespace c3po::cli
