#pragma once

// The command lines of the example and benchmark programs, parsed by CLI11 (libcli11-dev) with
// one convention: --help / -h prints the generated help on stdout and exits 0; a command line CLI11
// refuses (an unknown option, a missing or malformed value, an option given twice) prints
// "error: " and the reason on stderr, with a pointer to --help, and exits 2, the code every
// program here uses for a wrong command line.

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

namespace bundletrack::examples {

/// A program's command line: CLI11's App with the help laid out for this project's option texts
/// (values named as DIR, FILE, N; descriptions of several lines).
class CommandLine : public CLI::App {
 public:
  CommandLine(const std::string& description, const std::string& program) : CLI::App(description, program) {
    get_formatter()->column_width(26);
  }

  /// Parses argv into the options (see the header comment for --help and errors).
  void parseOrExit(int argc, char** argv) {
    try {
      parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
      std::cout << help();
      std::exit(0);
    } catch (const CLI::ParseError& error) {
      fail(error.what());
    }
  }

  /// Ends the program as a refused command line does, for what only the program can check
  /// (options that belong together, a value the settings table refuses).
  [[noreturn]] void fail(const std::string& message) const {
    std::cerr << "error: " << message << "\nrun " << get_name() << " --help for the options\n";
    std::exit(2);
  }
};

/// A value that reads as a finite number (a whole one where `whole`) for which `accepts` holds;
/// refused, its message names what was wanted and what was given, e.g.
/// "--frames: expects a whole number >= 1, got '2.5'". `wanted` also names the values in --help.
template <typename Accepts>
CLI::Validator numberCheck(const std::string& wanted, bool whole, Accepts accepts) {
  const std::string what = std::string(whole ? "a whole number " : "a number ") + wanted;
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double value = 0.0;
        std::size_t used = 0;
        try {
          value = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        const bool ok = used > 0 && used == text.size() && std::isfinite(value) && (!whole || value == std::floor(value)) &&
                        accepts(value);
        return ok ? std::string() : "expects " + what + ", got '" + text + "'";
      },
      wanted);
}

/// A whole number in [lowest, highest] (a choice among counts).
inline CLI::Validator wholeIn(int lowest, int highest) {
  return numberCheck("in [" + std::to_string(lowest) + ", " + std::to_string(highest) + "]", true,
                     [=](double value) { return value >= lowest && value <= highest; });
}

/// A whole number of at least `lowest` (counts, frame indices, seeds).
inline CLI::Validator wholeAtLeast(int lowest) {
  return numberCheck(">= " + std::to_string(lowest), true, [=](double value) { return value >= lowest; });
}

/// A positive number (metres, scales).
inline CLI::Validator positive() {
  return numberCheck("> 0", false, [](double value) { return value > 0.0; });
}

/// A probability: a number in [0, 1].
inline CLI::Validator probability() {
  return numberCheck("in [0, 1]", false, [](double value) { return value >= 0.0 && value <= 1.0; });
}

}  // namespace bundletrack::examples
