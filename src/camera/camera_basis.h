// The camera's rotation, view -> world (fogcl/camera.h CameraPose; docs/volumetric.md §World and
// rays): columns right, up', forward, in double. Written once for the passes that need it (the
// volume pass's frame, height fog's view-space constants); each rounds it to its own precision.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "fogcl/camera.h"

namespace fogcl::detail {

struct CameraBasis {
  glm::dvec3 right, up, forward;
};

// Whether up is (nearly) parallel to forward, which leaves no basis: the rule of every pose check
// (the library's validate, the CLI's flags). Both non-zero.
inline bool up_parallel_to_forward(const glm::vec3& up, const glm::vec3& forward) {
  return glm::length(glm::cross(glm::normalize(glm::dvec3(up)), glm::normalize(glm::dvec3(forward)))) < 1e-4;
}

// right = normalize(cross(up, forward)), up' = cross(forward, right), forward normalised.
inline CameraBasis camera_basis(const CameraPose& p) {
  const glm::dvec3 f = glm::normalize(glm::dvec3(p.forward));
  const glm::dvec3 r = glm::normalize(glm::cross(glm::dvec3(p.up), f));
  return {r, glm::cross(f, r), f};
}

}  // namespace fogcl::detail
