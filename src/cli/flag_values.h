// The grammar of flag values (docs/cli.md#errors), checked on the text as typed, when the command
// line is parsed: before any file is read or written.
//
//   malformed (exit 2): an empty value, text that is not a number, a wrong count of components;
//   a rule broken (exit 1): a well-formed value out of the flag's range, or not one of its keywords.
//
// Keywords are exact lowercase words; device names (--device) are matched as parts of the
// device's name in any case. Every message names the flag and shows the value as typed.
#pragma once

#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/frame_memory.h"
#include "cli/number_list.h"
#include "cli/sequence.h"
#include "cli/usage.h"

namespace fogcl::cli {

// Marks a check's message as a usage error for main's handler of CLI11's ValidationError.
constexpr char kMalformedMark = '\x01';

// A CLI11 check that runs `check(text)` on each value as typed, before CLI11 converts it; `check`
// throws UsageError (malformed) or fogcl::Error (a rule), each message naming the flag.
inline CLI::Validator value_check(std::function<void(const std::string&)> check) {
  return CLI::Validator(
      [check](std::string& text) -> std::string {
        try {
          check(text);
        } catch (const UsageError& e) {
          return kMalformedMark + std::string(e.what());
        } catch (const Error& e) {
          return e.what();
        }
        return "";
      },
      "");
}

// An empty value is malformed: "FLAG must not be empty (WHAT)".
inline void require_text(const std::string& flag, const std::string& text, const std::string& what) {
  if (text.empty()) throw UsageError(flag + " must not be empty (" + what + ")");
}

// The rule of a real-valued flag, on the value as a float: [lo, hi] or open ends.
struct RealRule {
  const char* text;  // "finite and > 0", as messages say it
  double lo = -DBL_MAX;
  bool lo_open = false;
  double hi = DBL_MAX;
  bool hi_open = false;
};
inline const RealRule kFinite{"finite"};
inline const RealRule kPositive{"finite and > 0", 0.0, true};
inline const RealRule kNonNegative{"finite and >= 0", 0.0, false};

// One number as strtod reads the whole text (nan and inf are numbers, for the rules to name);
// throws UsageError for empty text, a leading blank (as integer flags) or text that is not one number.
inline double read_number(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double d = std::strtod(text.c_str(), &end);
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0])) || end == text.c_str() || *end != '\0')
    throw UsageError(flag + " must be a number (got '" + text + "')");
  return d;
}

// A float flag's value: a number (else UsageError), finite within float's range and inside `rule`
// (else Error "FLAG must be RULE (got TEXT)"); the float it converts to.
inline float real_value(const std::string& flag, const std::string& text, const RealRule& rule) {
  const double d = read_number(flag, text);
  if (std::isfinite(d) && std::fabs(d) > double(FLT_MAX))
    throw Error(flag + " must be " + rule.text + " (got " + text + ", beyond float's range |x| <= 3.4e38)");
  const double f = double(float(d));
  const bool inside = std::isfinite(f) && (rule.lo_open ? f > rule.lo : f >= rule.lo) &&
                      (rule.hi_open ? f < rule.hi : f <= rule.hi);
  if (!inside) throw Error(flag + " must be " + rule.text + " (got " + text + ")");
  return float(f);
}

inline CLI::Validator real_check(const std::string& flag, const RealRule& rule) {
  return value_check([flag, rule](const std::string& text) { real_value(flag, text, rule); });
}

// One of `words`, exactly: "FLAG must be one of a, b or c (got 'X')", with a note when only the
// letter case differs.
inline std::string keyword_list(const std::vector<std::string>& words) {
  std::string list;
  for (std::size_t i = 0; i < words.size(); ++i)
    list += (i == 0 ? "" : i + 1 == words.size() ? " or " : ", ") + words[i];
  return list;
}
inline std::string lowercase(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}
inline void check_keyword(const std::string& flag, const std::string& text, const std::vector<std::string>& words) {
  require_text(flag, text, "one of " + keyword_list(words));
  for (const std::string& w : words)
    if (text == w) return;
  std::string note;
  for (const std::string& w : words)
    if (lowercase(text) == w) note = "; keywords are lowercase: " + w;
  throw Error(flag + " must be one of " + keyword_list(words) + " (got '" + text + "'" + note + ")");
}
inline CLI::Validator keyword_check(const std::string& flag, const std::vector<std::string>& words) {
  return value_check([flag, words](const std::string& text) { check_keyword(flag, text, words); });
}

// A comma-separated list of `words` ("demo,dense"); an empty part is malformed.
inline std::vector<std::string> keyword_list_value(const std::string& flag, const std::string& text,
                                                   const std::vector<std::string>& words) {
  require_text(flag, text, "a comma-separated list of " + keyword_list(words));
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (part.empty())
      throw UsageError(flag + " must be a comma-separated list of " + keyword_list(words) + " (got '" + text +
                       "', an empty part)");
    try {
      check_keyword(flag, part, words);
    } catch (const Error& e) {
      if (part == text) throw;
      throw Error(std::string(e.what()) + " in '" + text + "'");
    }
    parts.push_back(part);
    if (comma == std::string::npos) return parts;
    start = comma + 1;
  }
}

// A text value (a file name, a channel or layer name): only non-empty.
inline CLI::Validator text_check(const std::string& flag, const std::string& what) {
  return value_check([flag, what](const std::string& text) { require_text(flag, text, what); });
}

// --device: cpu, gpu, scalar, or part of a device name (any case). A keyword in other letters
// ("CPU") is refused rather than read as a name.
inline void check_device(const std::string& flag, const std::string& text) {
  require_text(flag, text, "cpu, gpu, scalar or part of an OpenCL device name");
  for (const char* w : {"cpu", "gpu", "scalar"})
    if (text != w && lowercase(text) == w)
      throw Error(flag + " must be cpu, gpu, scalar or part of a device name (got '" + text +
                  "'; keywords are lowercase: " + w + ")");
}

inline const char* const kDeviceHelp =
    "cpu (default: PoCL's CPU device), gpu, scalar (one-thread C++ path) or part of an OpenCL "
    "device name (any case); default from the FOGCL_DEVICE environment variable";

inline CLI::Validator device_check(const std::string& flag) {
  return value_check([flag](const std::string& text) { check_device(flag, text); });
}

// A file name that may hold a frame placeholder (cli/sequence.h): not empty, one valid placeholder.
inline CLI::Validator path_check(const std::string& flag, const std::string& what) {
  return value_check([flag, what](const std::string& text) {
    require_text(flag, text, what);
    try {
      parse_frame_pattern(text);
    } catch (const Error& e) {
      throw Error(flag + " " + e.what());
    }
  });
}

// --frames: "FRAME" or "FIRST-LAST" in digits (else malformed); the range rules are
// parse_frame_range's.
inline void check_frame_range_text(const std::string& text) {
  require_text("--frames", text, "FRAME or FIRST-LAST");
  const std::size_t dash = text.find('-');
  const std::string a = text.substr(0, dash), b = dash == std::string::npos ? a : text.substr(dash + 1);
  for (const std::string& s : {a, b})
    if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos)
      throw UsageError("--frames must be FRAME or FIRST-LAST, whole numbers (got '" + text + "')");
  parse_frame_range(text);
}

// --max-memory: a number and a unit (else malformed); the size rules are parse_memory_size's.
inline void check_memory_size_text(const std::string& text) {
  require_text("--max-memory", text, "a size such as 8G or 512M");
  if (!std::isdigit(static_cast<unsigned char>(text[0])))
    throw UsageError("--max-memory must be a size such as 8G, 512M or 1.5GiB (got '" + text + "')");
  parse_memory_size(text);
}

// "16,32": step counts, each an integer in [1, 4096].
inline std::vector<int> parse_step_list(const std::string& flag, const std::string& text) {
  require_text(flag, text, "step counts such as 16,32");
  std::vector<int> steps;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (part.empty() || part.find_first_not_of("0123456789") != std::string::npos)
      throw UsageError(flag + " must be comma-separated whole numbers such as 16,32 (got '" + text + "')");
    const long long v = part.size() > 9 ? 0 : std::stoll(part);
    if (v < 1 || v > 4096) throw Error(flag + " must be in [1, 4096] (got " + part + " in '" + text + "')");
    steps.push_back(int(v));
    if (comma == std::string::npos) return steps;
    start = comma + 1;
  }
}

}  // namespace fogcl::cli
