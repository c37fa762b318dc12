// The doctest main of every unit test executable. ctest runs each case as
// `EXE --test-case=NAME` (doctest_discover_tests); doctest reads a filter
// matching nothing as success, so a name that the discovery mangles (doctest
// 2.4.9 splits names at ';') would pass without running. Here a run with a
// test-case filter that runs no case fails instead.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <cstdio>
#include <cstring>

namespace {

// How many test cases the last run selected; -1 before a run ends (listing
// queries such as --list-test-suites end without one).
int g_selected_cases = -1;

struct SelectedCasesListener : doctest::IReporter {
  explicit SelectedCasesListener(const doctest::ContextOptions&) {}
  void report_query(const doctest::QueryData&) override {}
  void test_run_start() override {}
  void test_run_end(const doctest::TestRunStats& stats) override {
    g_selected_cases = static_cast<int>(stats.numTestCasesPassingFilters);
  }
  void test_case_start(const doctest::TestCaseData&) override {}
  void test_case_reenter(const doctest::TestCaseData&) override {}
  void test_case_end(const doctest::CurrentTestCaseStats&) override {}
  void test_case_exception(const doctest::TestCaseException&) override {}
  void subcase_start(const doctest::SubcaseSignature&) override {}
  void subcase_end() override {}
  void log_assert(const doctest::AssertData&) override {}
  void log_message(const doctest::MessageData&) override {}
  void test_case_skipped(const doctest::TestCaseData&) override {}
};

bool HasTestCaseFilter(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::strncmp(argv[i], "--test-case=", 12) == 0 || std::strncmp(argv[i], "-tc=", 4) == 0) return true;
  }
  return false;
}

}  // namespace

REGISTER_LISTENER("selected_cases", 1, SelectedCasesListener);

int main(int argc, char** argv) {
  doctest::Context context(argc, argv);
  const int status = context.run();
  if (context.shouldExit()) return status;
  if (status == 0 && g_selected_cases == 0 && HasTestCaseFilter(argc, argv)) {
    std::fprintf(stderr, "test_main: the --test-case filter selects no test case (a mangled name?)\n");
    return 1;
  }
  return status;
}
