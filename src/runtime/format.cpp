#include "runtime/format.h"

#include <sstream>

namespace fogcl::detail {

std::string str(double v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

std::string str(const glm::vec3& v) { return "(" + str(v.x) + ", " + str(v.y) + ", " + str(v.z) + ")"; }
std::string str(const glm::dvec3& v) { return "(" + str(v.x) + ", " + str(v.y) + ", " + str(v.z) + ")"; }
std::string str(const glm::vec4& v) {
  return "(" + str(v.x) + ", " + str(v.y) + ", " + str(v.z) + ", " + str(v.w) + ")";
}

std::string comma_list(const glm::vec3& v) { return str(v.x) + "," + str(v.y) + "," + str(v.z); }

}  // namespace fogcl::detail
