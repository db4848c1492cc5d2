// VOLUMES.json, the fog volumes of a scene as a file (docs/cli.md#volumesjson), part of fogcl::io:
//   {"volumes": [{"center": [x, y, z], "radius": r, ...}, ...]}
// each key a FogVolume field (fogcl/volumes.h) in snake_case.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fogcl/volumes.h"

namespace fogcl {

// The volumes of the JSON `text`; `name` (a file name) begins every message. Throws fogcl::Error,
// one line: "NAME: volume I: 'KEY' RULE (got VALUE)" for a wrong value, "NAME: malformed JSON: parse
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
std::vector<FogVolume> read_volumes_json(const std::string& path);

// The inverse: every key of each volume (albedo and ambient only when set), as the shortest
// decimals that read back as the same floats: parse_volumes_json gives the volumes back exactly.
std::string volumes_to_json(const std::vector<FogVolume>& volumes);

}  // namespace fogcl
