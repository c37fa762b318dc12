#pragma once
// Every subcommand file (cli/<name>.cpp) defines one Setup function: it
// declares the subcommand's options on `command`, binding them to an options
// struct it owns, and returns the function that validates, calls the library
// and reports. Run functions return the exit status; they throw
// c3po::InputError for bad input (main prints "c3po NAME: message", exit 2).
#include <CLI/CLI.hpp>
#include <functional>

namespace c3po::cli {

using RunFunction = std::function<int()>;

RunFunction SetupAnnotate(CLI::App& command);
RunFunction SetupIndicators(CLI::App& command);
RunFunction SetupSynth(CLI::App& command);
RunFunction SetupTrain(CLI::App& command);
RunFunction SetupSelftrain(CLI::App& command);
RunFunction SetupCertify(CLI::App& command);
RunFunction SetupEval(CLI::App& command);
RunFunction SetupBench(CLI::App& command);
RunFunction SetupDemo(CLI::App& command);
RunFunction SetupMerge(CLI::App& command);

}  // namespace c3po::cli
