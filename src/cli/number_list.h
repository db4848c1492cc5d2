// Comma-separated numbers on the command line ("1,0.5,2", 16 matrix elements): the splitting the
// flags share; each flag keeps its own count, range and messages.
#pragma once

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "cli/usage.h"
#include "fogcl/error.h"

namespace fogcl::cli {

struct NumberList {
  std::vector<double> numbers;          // the parts read so far, in order
  std::optional<std::string> bad_part;  // the first part that is not a number (index numbers.size())
};

// Each part between commas as strtod reads the whole of it (so nan, inf and 1e39 are numbers, for
// the flag's rules to name them); stops at the first part that is empty, starts with a blank
// (numbers are written without, as for single-number flags) or has anything after the number.
inline NumberList parse_number_list(const std::string& text) {
  NumberList list;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    char* end = nullptr;
    const double d = std::strtod(part.c_str(), &end);
    if (part.empty() || std::isspace(static_cast<unsigned char>(part[0])) || end == part.c_str() || *end != '\0') {
      list.bad_part = std::move(part);
      return list;
    }
    list.numbers.push_back(d);
    if (comma == std::string::npos) return list;
    start = comma + 1;
  }
}

// Exactly `count` numbers for `flag`, or one usage error (malformed) naming the flag: "FLAG
// element I is not a number (got 'X'; expected WHAT)" or "FLAG must be WHAT (got N numbers)".
inline std::vector<double> parse_numbers(const std::string& flag, const std::string& text, std::size_t count,
                                         const std::string& what) {
  NumberList list = parse_number_list(text);
  if (list.bad_part)
    throw UsageError(flag + " element " + std::to_string(list.numbers.size()) + " is not a number (got '" +
                     *list.bad_part + "'; expected " + what + ")");
  if (list.numbers.size() != count)
    throw UsageError(flag + " must be " + what + " (got " + std::to_string(list.numbers.size()) + " numbers)");
  return std::move(list.numbers);
}

// "X,Y,Z": exactly three numbers for `flag`, or the usage error (malformed) "FLAG must be three
// comma-separated numbers NAMES (got 'TEXT')"; each flag checks the range itself.
inline glm::dvec3 parse_triple(const std::string& flag, const std::string& text, const char* names = "X,Y,Z") {
  const NumberList list = parse_number_list(text);
  if (list.bad_part || list.numbers.size() != 3)
    throw UsageError(flag + " must be three comma-separated numbers " + names + " (got '" + text + "')");
  return {list.numbers[0], list.numbers[1], list.numbers[2]};
}

// "X,Y,Z" -> three finite floats, or "FLAG must be finite (got 'TEXT')" (as floats: 1e39 is inf).
inline glm::vec3 parse_finite_vec3(const std::string& flag, const std::string& text) {
  const glm::dvec3 d = parse_triple(flag, text);
  for (int k = 0; k < 3; ++k)
    if (!(std::isfinite(d[k]) && std::fabs(d[k]) <= 3.4028234663852886e38))
      throw Error(flag + " must be finite in float, |x| <= 3.4e38 (got '" + text + "')");
  return glm::vec3(d);
}

// parse_finite_vec3, and a direction the library can normalise in float: not (0, 0, 0) ("FLAG
// must be a non-zero vector"), its length neither 0 (components of 1e-45 square to 0) nor beyond
// float's range ("FLAG is too short / too long to normalise").
inline glm::vec3 parse_direction(const std::string& flag, const std::string& text) {
  const glm::vec3 v = parse_finite_vec3(flag, text);
  if (v == glm::vec3(0.0f)) throw Error(flag + " must be a non-zero vector (got '" + text + "')");
  const float length = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);  // glm::length's float sum
  if (length == 0.0f)
    throw Error(flag + " is too short to normalise: its length is 0 in float (got '" + text +
                "'; the squares of its components underflow)");
  if (!std::isfinite(length))
    throw Error(flag + " is too long to normalise: its length overflows float (got '" + text + "')");
  return v;
}

}  // namespace fogcl::cli
