// VOLUMES.json, the fog volumes and local lights of a scene as a file (docs/cli.md#volumesjson),
// part of fogcl::io:
//   {"volumes": [{"center": [x, y, z], "radius": r, ...}, ...],
//    "lights": [{"type": "point", "position": [x, y, z], "intensity": i, "range": r, ...}, ...]}
// each key a FogVolume or LocalLight field (fogcl/volumes.h) in snake_case; "lights" is optional.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fogcl/volumes.h"

namespace fogcl {

// What a VOLUMES.json holds (VolumeScene's volumes and lights).
struct VolumesFile {
  std::vector<FogVolume> volumes;
  std::vector<LocalLight> lights;
};

// The volumes and lights of the JSON `text`; `name` (a file name) begins every message. Throws
// fogcl::Error, one line: "NAME: volume I: 'KEY' RULE (got VALUE)" or "NAME: light I: 'KEY' RULE
// (got VALUE)" for a wrong value, "NAME: malformed JSON: parse error at line L, column C: ..." for
// malformed JSON, "NAME: JSON nested deeper than 64 levels ..." before parsing text nested deeper.
// Every volume and light also passes fogcl::validate(). A light needs "type" ("point" or "spot")
// and "position"; a point light refuses the cone's keys (direction, inner_angle, outer_angle).
VolumesFile parse_volumes_file(const std::string& text, const std::string& name);

// The volumes of a file without lights (one with lights is refused, naming parse_volumes_file:
// its lights are never dropped unsaid); `name` (a file name) begins every message. Throws
// fogcl::Error, one line: "NAME: volume I: 'KEY' RULE (got VALUE)" for a wrong value, "NAME: malformed JSON: parse
// error at line L, column C: ..." for malformed JSON, "NAME: JSON nested deeper than 64 levels ..."
// before parsing text nested deeper. Every volume also passes fogcl::validate(). One key that is
// not a field: "medium": "homogeneous" (a plain medium: noise and fades off, albedo and ambient 0
// unless given; it refuses the noise and fade keys). The values are as given (no axes mapping).
std::vector<FogVolume> parse_volumes_json(const std::string& text, const std::string& name);

// The largest VOLUMES.json read_volumes_json reads: a volume takes a few hundred bytes.
inline constexpr std::uint64_t kMaxVolumesJsonBytes = std::uint64_t(64) << 20;

// The volumes of the file at `path`, which must be a regular file of at most kMaxVolumesJsonBytes:
// checked before a byte is read, so /dev/zero, a FIFO, a directory or a huge file is refused in one
// line naming the file and what it is or its size. The messages name fogcl apply's flag
// (--volumes), as the command line reports them.
VolumesFile read_volumes_file(const std::string& path);
// read_volumes_file's volumes; a file with lights is refused as parse_volumes_json refuses it.
std::vector<FogVolume> read_volumes_json(const std::string& path);

// The inverse: every key of each volume (albedo and ambient only when set), as the shortest
// decimals that read back as the same floats: parse_volumes_json gives the volumes back exactly.
std::string volumes_to_json(const std::vector<FogVolume>& volumes);
// ... with the lights (every key of each, the cone's for spot lights only; no "lights" when there
// are none): parse_volumes_file gives both back exactly.
std::string volumes_to_json(const std::vector<FogVolume>& volumes, const std::vector<LocalLight>& lights);
std::string volumes_to_json(const VolumesFile& file);

}  // namespace fogcl
