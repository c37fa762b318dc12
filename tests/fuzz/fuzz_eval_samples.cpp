// libFuzzer target: the eval samples reader (c3po merge --eval) on arbitrary
// bytes, as one part and as the second of two parts (after a valid first
// part from the seed corpus, when the input splits at a NUL byte).
#include "c3po/base/error.hpp"
#include "c3po/eval/evaluation_samples.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text = c3po_fuzz::Bytes(data, size);
  const std::size_t split = text.find('\0');
  try {
    if (split == std::string::npos) {
      const c3po::Evaluation e = c3po::MergeEvaluationSamples({{"part.jsonl", text}});
      (void)c3po::EvaluationTable(e);
      (void)c3po::EvaluationJson(e);
    } else {
      const c3po::Evaluation e = c3po::MergeEvaluationSamples(
          {{"a.jsonl", text.substr(0, split)}, {"b.jsonl", text.substr(split + 1)}});
      (void)c3po::EvaluationTable(e);
    }
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
