// Usage errors and integer flags of the fogcl command line.
//
// Exit codes: 0 done; 1 an error (a well-formed value that breaks a rule, a bad or unreadable file,
// a failed frame, a device that fails); 2 a usage error (an unknown option, a malformed value:
// empty, not a number, a wrong count of components; an option given twice, a required option left
// out); 128 + N stopped by signal N.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "fogcl/error.h"

namespace fogcl::cli {

constexpr int kExitError = 1;
constexpr int kExitUsage = 2;

// The exit codes as --help lists them (every command's footer).
inline const char* exit_codes_help() {
  return "Exit codes: 0 done; 1 error (a well-formed value that breaks a rule: out of range, not one of the "
         "keywords, which are lowercase; a bad or unreadable file, a failed frame, a device error); 2 usage error "
         "(unknown option, a malformed value: empty, not a number, a wrong count of components; option given "
         "twice, required option missing); 128+N stopped by signal N (130 Ctrl-C, 143 SIGTERM).";
}

// A usage error (exit code 2): a malformed value, or a required option left out.
class UsageError : public Error {
 public:
  using Error::Error;
};

// A check for an integer flag, run on the text before it is converted: a well-formed integer
// outside [lo, hi] (or, with `allowed`, not one of those) fails with "must be RULE (got TEXT)", the
// text as given (so a number too large for any integer type is shown, not clamped; exit code 1, a
// rule). Empty text or text that is not an integer is malformed (exit code 2; the message carries
// the mark of cli/flag_values.h).
inline CLI::Validator integer_in(long long lo, long long hi, const std::string& rule,
                                 std::vector<long long> allowed = {}) {
  return CLI::Validator(
      [lo, hi, rule, allowed](std::string& text) -> std::string {
        const std::size_t i = (!text.empty() && (text[0] == '-' || text[0] == '+')) ? 1 : 0;
        bool digits = i < text.size();
        for (std::size_t k = i; k < text.size(); ++k) digits = digits && text[k] >= '0' && text[k] <= '9';
        if (!digits) return "\x01must be an integer, " + rule + " (got '" + text + "')";
        errno = 0;
        const long long v = std::strtoll(text.c_str(), nullptr, 10);
        bool ok = errno != ERANGE && v >= lo && v <= hi;
        if (ok && !allowed.empty()) ok = std::find(allowed.begin(), allowed.end(), v) != allowed.end();
        if (!ok) return "must be " + rule + " (got " + text + ")";
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
