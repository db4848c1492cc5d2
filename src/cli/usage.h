// Usage errors and integer flags of the fogcl command line.
//
// Exit codes: 0 done; 1 an error (a value that breaks a rule, a bad or unreadable file, a failed
// frame, a device that fails); 2 a usage error (an unknown option, a missing or non-numeric
// argument, an option given twice, a required option left out); 128 + N stopped by signal N.
#pragma once

#include <cerrno>
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>

#include "fogcl/error.h"

namespace fogcl::cli {

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;

// The exit codes as --help lists them (every command's footer).
inline const char* exit_codes_help() {
  return "Exit codes: 0 done; 1 error (a value that breaks a rule, a bad or unreadable file, a failed frame, a "
         "device error); 2 usage error (unknown option, missing or non-numeric argument, option given twice, "
         "required option missing); 128+N stopped by signal N (130 Ctrl-C, 143 SIGTERM).";
}

// A usage error (exit code 2) found after parsing: a required option left out.
class UsageError : public Error {
 public:
  using Error::Error;
};

// A check for an integer flag, run on the text before it is converted: a well-formed integer
// outside [lo, hi] fails with "must be RULE (got TEXT)", the text as given (so a number too large
// for any integer type is shown, not clamped; exit code 1, a rule). Text that is not an integer
// passes, for the conversion to refuse (a usage error).
inline CLI::Validator integer_in(long long lo, long long hi, const std::string& rule) {
  return CLI::Validator(
      [lo, hi, rule](std::string& text) -> std::string {
        std::size_t i = (!text.empty() && (text[0] == '-' || text[0] == '+')) ? 1 : 0;
        if (i == text.size()) return "";
        for (std::size_t k = i; k < text.size(); ++k)
          if (text[k] < '0' || text[k] > '9') return "";
        errno = 0;
        const long long v = std::strtoll(text.c_str(), nullptr, 10);
        if (errno == ERANGE || v < lo || v > hi) return "must be " + rule + " (got " + text + ")";
        return "";
      },
      "");
}

// The text a flag was given as (its last occurrence), for messages that show it as typed.
inline std::string flag_value(const CLI::App& app, const std::string& flag) {
  const CLI::Option* option = app.get_option_no_throw(flag);
  return option == nullptr || option->results().empty() ? std::string() : option->results().back();
}

}  // namespace fogcl::cli
