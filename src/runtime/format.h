// Numbers in error messages, one format everywhere: 9 significant digits (enough for a float to
// read back as the same float), the stream's default notation ("0.1", "1e+30", "inf", "nan").
#pragma once

#include <string>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace fogcl::detail {

std::string str(double v);  // a float widens exactly: the same digits as the float itself

// "(x, y, z)" and "(x, y, z, w)", each component as str(double).
std::string str(const glm::vec3& v);
std::string str(const glm::dvec3& v);
std::string str(const glm::vec4& v);

// "x,y,z": a vector as the CLI's flags take it.
std::string comma_list(const glm::vec3& v);

}  // namespace fogcl::detail
