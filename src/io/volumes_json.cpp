// VOLUMES.json (docs/cli.md#volumesjson): the fog volumes of a scene as a file, read and written.
// nlohmann-json parses it; it stays private to this file (a build dependency of fogcl::io only).
#include "fogcl/volumes_json.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "fogcl/error.h"
#include "io/atomic_file.h"
#include "runtime/format.h"

namespace fogcl {

namespace {

using nlohmann::json;

using detail::str;

using Member = std::variant<float FogVolume::*, glm::vec3 FogVolume::*, glm::vec4 FogVolume::*, bool FogVolume::*,
                            std::optional<glm::vec3> FogVolume::*>;

// Every FogVolume field by its snake_case name (fogcl/volumes.h documents units and ranges).
const std::map<std::string, Member>& volume_fields() {
  static const std::map<std::string, Member> fields{
      {"center", &FogVolume::center},
      {"radius", &FogVolume::radius},
      {"density", &FogVolume::density},
      {"max_y", &FogVolume::max_y},
      {"fade_y", &FogVolume::fade_y},
      {"fade_edge", &FogVolume::fade_edge},
      {"proximity_fade", &FogVolume::proximity_fade},
      {"fog_exponent", &FogVolume::fog_exponent},
      {"fog_cutoff", &FogVolume::fog_cutoff},
      {"detail_exponent", &FogVolume::detail_exponent},
      {"detail_strength", &FogVolume::detail_strength},
      {"fog_color", &FogVolume::fog_color},
      {"directional_fog_color", &FogVolume::directional_fog_color},
      {"directional_falloff", &FogVolume::directional_falloff},
      {"light_contribution", &FogVolume::light_contribution},
      {"directional_light_contribution", &FogVolume::directional_light_contribution},
      {"shadow_strength", &FogVolume::shadow_strength},
      {"shadow_reverse_strength", &FogVolume::shadow_reverse_strength},
      {"tiling", &FogVolume::tiling},
      {"speed", &FogVolume::speed},
      {"detail_tiling", &FogVolume::detail_tiling},
      {"detail_speed_modifier", &FogVolume::detail_speed_modifier},
      {"occluder_overshoot", &FogVolume::occluder_overshoot},
      {"noise", &FogVolume::noise},
      {"albedo", &FogVolume::albedo},
      {"anisotropy", &FogVolume::anisotropy},
      {"ambient", &FogVolume::ambient},
  };
  return fields;
}

// A key from the file as a message quotes it: control bytes (a NUL would end the message) as JSON
// escapes, cut to stay one short line.
std::string key_text(const std::string& key) {
  std::string s;
  for (const char c : key) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned char>(c));
      s += buf;
    } else {
      s += c;
    }
  }
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

// Levenshtein distance, for "did you mean" on an unknown key.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// A JSON value in a message: numbers as numbers, the rest as JSON text, cut to stay one short line.
std::string shown(const json& j) {
  std::string s = j.is_number() ? str(j.get<double>()) : j.dump();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

// Reads the keys of one volume; every failure names the file, the volume, the key and the rule.
struct KeyReader {
  std::string where;  // "FILE: volume I: "

  [[noreturn]] void fail(const std::string& key, const std::string& rule, const std::string& got) const {
    throw Error(where + "'" + key + "' " + rule + " (got " + got + ")");
  }
  // A float: a JSON number, finite in float (JSON has no NaN or Inf; 1e39 would become inf).
  float real(const std::string& key, const json& j) const {
    if (!j.is_number()) fail(key, "must be a number", shown(j));
    const double v = j.get<double>();
    if (!(std::isfinite(v) && std::fabs(v) <= double(FLT_MAX)))
      fail(key, "must be a finite number within float range (|x| <= 3.4e38)", shown(j));
    return float(v);
  }
  // An array of n numbers, or of any count in [lo, hi] for colors.
  std::vector<float> reals(const std::string& key, const json& j, std::size_t lo, std::size_t hi,
                           const char* rule) const {
    if (!j.is_array() || j.size() < lo || j.size() > hi) fail(key, rule, shown(j));
    std::vector<float> out;
    for (std::size_t k = 0; k < j.size(); ++k) out.push_back(real(key + "[" + std::to_string(k) + "]", j[k]));
    return out;
  }
  glm::vec3 vec3(const std::string& key, const json& j) const {
    const std::vector<float> v = reals(key, j, 3, 3, "must be an array of 3 numbers [x, y, z]");
    return glm::vec3(v[0], v[1], v[2]);
  }
  // Colors: RGBA, or RGB with alpha 1.
  glm::vec4 color(const std::string& key, const json& j) const {
    const std::vector<float> v = reals(key, j, 3, 4, "must be an array of 3 or 4 numbers [r, g, b(, a)]");
    return glm::vec4(v[0], v[1], v[2], v.size() == 4 ? v[3] : 1.0f);
  }
  bool boolean(const std::string& key, const json& j) const {
    if (!j.is_boolean()) fail(key, "must be true or false", shown(j));
    return j.get<bool>();
  }
};

// The keys a homogeneous medium refuses, and why.
const std::map<std::string, std::string> kNotHomogeneous{
    {"noise", "it has no noise"},
    {"fade_edge", "it has no fades"},
    {"proximity_fade", "it has no fades"},
    {"fade_y", "it has no fades"},
    {"max_y", "it has no height fade"},
    {"fog_exponent", "it has no noise to shape"},
    {"fog_cutoff", "it has no noise to shape"},
    {"detail_exponent", "it has no noise to shape"},
    {"detail_strength", "it has no noise to shape"},
    {"tiling", "it has no noise to shape"},
    {"speed", "it has no noise to shape"},
    {"detail_tiling", "it has no noise to shape"},
    {"detail_speed_modifier", "it has no noise to shape"},
};
// A homogeneous medium's max_y: fogcl::validate's largest (|max_y| <= 3.4e38).
constexpr float kHomogeneousMaxY = 3.4e38f;

FogVolume parse_volume(const json& j, const KeyReader& r) {
  if (!j.is_object())
    throw Error(r.where + "must be an object {\"center\": [x, y, z], \"radius\": r, ...} (got " + shown(j) + ")");
  if (!j.contains("center")) throw Error(r.where + "'center' is missing (every volume needs \"center\": [x, y, z])");
  if (!j.contains("radius")) throw Error(r.where + "'radius' is missing (every volume needs \"radius\": r > 0)");
  FogVolume v;
  // "medium": "homogeneous": a plain medium in one key. The seed's defaults are a stylized look
  // (noise, three fades, albedo = fog colour, ambient 0.1 x light); a homogeneous medium is the
  // sphere at constant density: no noise, no fades (no height ceiling), and lit only as asked:
  // albedo 0 (a pure absorber) and ambient 0 unless "albedo" / "ambient" say otherwise. The keys
  // that would make it inhomogeneous (noise and fades) or that only shape noise are refused with it.
  const bool homogeneous = j.contains("medium");
  if (homogeneous) {
    const json& m = j["medium"];
    if (!m.is_string() || m.get<std::string>() != "homogeneous")
      r.fail("medium", "must be \"homogeneous\" (a plain medium: no noise, no fades, albedo and ambient 0 unless "
             "given; leave the key out for the seed's noisy, faded fog)", shown(m));
    v.noise = false;
    v.fade_edge = 0.0f;
    v.proximity_fade = 0.0f;
    v.fade_y = 0.0f;
    v.max_y = kHomogeneousMaxY;  // with fade_y 0 a hard ceiling, above anything finite a scene holds
    v.albedo = glm::vec3(0.0f);
    v.ambient = glm::vec3(0.0f);
  }
  for (const auto& item : j.items()) {
    // Named copies, not structured bindings: lambdas below use them (C++17 cannot capture bindings).
    const std::string key = item.key();
    const nlohmann::json& value = item.value();
    if (key == "medium") continue;  // read above
    if (homogeneous && kNotHomogeneous.count(key) > 0)
      r.fail(key, "does not go with \"medium\": \"homogeneous\" (" + kNotHomogeneous.at(key) +
             "; remove the key, or the medium for the seed's fog)", shown(value));
    const auto field = volume_fields().find(key);
    if (field == volume_fields().end()) {
      std::string best;
      std::size_t best_d = 4;  // suggest only close names
      for (const auto& f : volume_fields()) {
        const std::size_t d = edit_distance(key, f.first);
        if (d < best_d) best = f.first, best_d = d;
      }
      throw Error(r.where + "unknown key '" + key_text(key) + "' (" + (best.empty() ? "" : "did you mean '" + best + "'? ") +
                  "the keys are FogVolume's fields in snake_case: docs/cli.md#volumesjson)");
    }
    std::visit(
        [&](auto member) {
          using T = std::remove_reference_t<decltype(v.*member)>;
          if constexpr (std::is_same_v<T, float>) v.*member = r.real(key, value);
          if constexpr (std::is_same_v<T, glm::vec3>) v.*member = r.vec3(key, value);
          if constexpr (std::is_same_v<T, glm::vec4>) v.*member = r.color(key, value);
          if constexpr (std::is_same_v<T, bool>) v.*member = r.boolean(key, value);
          if constexpr (std::is_same_v<T, std::optional<glm::vec3>>) v.*member = r.vec3(key, value);
        },
        field->second);
  }
  // The sign rules users hit first, in the file's words; then every range of the library.
  if (!(v.radius > 0.0f)) r.fail("radius", "must be > 0", shown(j["radius"]));
  if (v.density < 0.0f) r.fail("density", "must be >= 0", shown(j["density"]));
  return v;
}

// Every LocalLight field by its snake_case name, but the kind ("type").
using LightMember = std::variant<float LocalLight::*, glm::vec3 LocalLight::*>;
const std::map<std::string, LightMember>& light_fields() {
  static const std::map<std::string, LightMember> fields{
      {"position", &LocalLight::position}, {"color", &LocalLight::color},
      {"intensity", &LocalLight::intensity}, {"range", &LocalLight::range},
      {"radius", &LocalLight::radius},       {"direction", &LocalLight::direction},
      {"inner_angle", &LocalLight::inner_angle}, {"outer_angle", &LocalLight::outer_angle},
  };
  return fields;
}
// The keys of a spot light's cone, refused on a point light (they would be silently unused).
bool spot_only(const std::string& key) { return key == "direction" || key == "inner_angle" || key == "outer_angle"; }

LocalLight parse_light(const json& j, const KeyReader& r) {
  if (!j.is_object())
    throw Error(r.where + "must be an object {\"type\": \"point\", \"position\": [x, y, z], ...} (got " + shown(j) +
                ")");
  if (!j.contains("type")) throw Error(r.where + "'type' is missing (every light needs \"type\": \"point\" or \"spot\")");
  if (!j.contains("position"))
    throw Error(r.where + "'position' is missing (every light needs \"position\": [x, y, z])");
  LocalLight l;
  const json& type = j["type"];
  if (type == "point")
    l.kind = LightKind::point;
  else if (type == "spot")
    l.kind = LightKind::spot;
  else
    r.fail("type", "must be \"point\" or \"spot\"", shown(type));
  for (const auto& item : j.items()) {
    const std::string key = item.key();
    const json& value = item.value();
    if (key == "type") continue;
    const auto field = light_fields().find(key);
    if (field == light_fields().end()) {
      std::string best;
      std::size_t best_d = 4;
      for (const auto& f : light_fields()) {
        const std::size_t d = edit_distance(key, f.first);
        if (d < best_d) best = f.first, best_d = d;
      }
      throw Error(r.where + "unknown key '" + key_text(key) + "' (" +
                  (best.empty() ? "" : "did you mean '" + best + "'? ") +
                  "the keys are \"type\" and LocalLight's fields in snake_case: docs/cli.md#volumesjson)");
    }
    if (l.kind == LightKind::point && spot_only(key))
      r.fail(key, "is for spot lights only (\"type\": \"spot\"; a point light has no cone)", shown(value));
    std::visit(
        [&](auto member) {
          using T = std::remove_reference_t<decltype(l.*member)>;
          if constexpr (std::is_same_v<T, float>) l.*member = r.real(key, value);
          if constexpr (std::is_same_v<T, glm::vec3>) l.*member = r.vec3(key, value);
        },
        field->second);
  }
  return l;
}

// The path of what the parser was reading when it failed, from the callback's key events.
struct ParseContext {
  std::string top_key;                      // last key of the top-level object
  std::string item_key;                     // last key of the current volume or light object
  int item = -1;                            // index of the current volume or light object
  std::vector<std::set<std::string>> keys;  // keys seen in each open object (duplicates)
  std::string duplicate;                    // "volume 1: duplicate key 'radius'"

  // "volume" or "light": what the objects of the current top-level array are.
  std::string noun() const { return top_key == "lights" ? "light" : "volume"; }
  bool in_items() const { return (top_key == "volumes" || top_key == "lights") && item >= 0; }
  std::string where() const {
    if (in_items())
      return noun() + " " + std::to_string(item) + (item_key.empty() ? "" : ": '" + key_text(item_key) + "'");
    return top_key.empty() ? "top level" : "top level: '" + key_text(top_key) + "'";
  }
};

// Deeper nesting than this is refused before parsing: nlohmann's parser and the code that prints
// a value (shown()) recurse once per level, so 100 000 '[' overflowed the stack. A volumes file
// nests 4 levels (the top object, "volumes", a volume, a vector); 64 leaves room for any mistake
// worth a specific message.
constexpr int kMaxJsonDepth = 64;

// Throws "NAME: JSON nested deeper than 64 levels at line L, column C ..." for text whose arrays
// and objects nest deeper than kMaxJsonDepth (outside strings); leaves every other error to the parser.
void check_json_depth(const std::string& text, const std::string& name) {
  int depth = 0;
  long line = 1, column = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    ++column;
    if (c == '\n') line += 1, column = 0;
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw Error(name + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels at line " +
                    std::to_string(line) + ", column " + std::to_string(column) +
                    " (a volumes file needs 4: {\"volumes\": [{\"center\": [x, y, z]}]})");
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
}

// The volumes of a file that has no lights: the volumes-only readers never drop a light unsaid.
std::vector<FogVolume> volumes_alone(VolumesFile file, const std::string& name) {
  if (!file.lights.empty())
    throw Error(name + ": has " + std::to_string(file.lights.size()) +
                " lights, which a reader of the volumes alone would drop: read it with read_volumes_file / "
                "parse_volumes_file (fogcl/volumes_json.h)");
  return std::move(file.volumes);
}

}  // namespace

VolumesFile parse_volumes_file(const std::string& text, const std::string& name) {
  check_json_depth(text, name);
  ParseContext ctx;
  // Depths as nlohmann counts them: the top object 0, its keys 1, volume objects 2, their keys 3.
  const json::parser_callback_t track = [&ctx](int depth, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        ctx.keys.emplace_back();
        if (depth == 2 && (ctx.top_key == "volumes" || ctx.top_key == "lights")) ++ctx.item, ctx.item_key.clear();
        break;
      case json::parse_event_t::object_end:
        if (!ctx.keys.empty()) ctx.keys.pop_back();
        break;
      case json::parse_event_t::key: {
        const std::string key = parsed.get<std::string>();
        if (depth == 1 && key != ctx.top_key) ctx.top_key = key, ctx.item = -1;
        if (depth == 3) ctx.item_key = key;
        // nlohmann keeps the last of repeated keys; a repeat is almost always a mistake.
        if (!ctx.keys.empty() && !ctx.keys.back().insert(key).second && ctx.duplicate.empty())
          ctx.duplicate = (depth == 3 && ctx.in_items() ? ctx.noun() + " " + std::to_string(ctx.item) + ": " : std::string()) +
                          "duplicate key '" + key_text(key) + "' (each key may appear once)";
        break;
      }
      default:
        break;
    }
    return true;
  };
  json doc;
  try {
    doc = json::parse(text, track);
  } catch (const json::parse_error& e) {
    // "[json.exception.parse_error.101] parse error at line 2, column 12: ..." without the tag.
    std::string what = e.what();
    const std::size_t tag = what.find("] ");
    if (tag != std::string::npos) what = what.substr(tag + 2);
    throw Error(name + ": malformed JSON: " + what);
  } catch (const json::exception& e) {
    // 1e999 and the like: nlohmann refuses numbers that overflow a double (406), without a position.
    std::string what = e.what();
    const std::size_t tag = what.find("] ");
    if (tag != std::string::npos) what = what.substr(tag + 2);
    throw Error(name + ": " + ctx.where() + " must be a finite number (" + what + ")");
  }
  if (!ctx.duplicate.empty()) throw Error(name + ": " + ctx.duplicate);
  if (!doc.is_object())
    throw Error(name + ": the top level must be an object {\"volumes\": [...]} (got " + shown(doc) + ")");
  for (const auto& [key, value] : doc.items())
    if (key != "volumes" && key != "lights")
      throw Error(name + ": top level: unknown key '" + key_text(key) + "' (the keys are \"volumes\" and \"lights\")");
  if (!doc.contains("volumes")) throw Error(name + ": top level: 'volumes' is missing (expected {\"volumes\": [...]})");
  const json& list = doc["volumes"];
  if (!list.is_array())
    throw Error(name + ": top level: 'volumes' must be an array of volume objects (got " + shown(list) + ")");
  VolumesFile file;
  for (std::size_t i = 0; i < list.size(); ++i) {
    file.volumes.push_back(parse_volume(list[i], KeyReader{name + ": volume " + std::to_string(i) + ": "}));
    try {
      validate(file.volumes.back(), i);  // "volume I: KEY RULE (got V)"
    } catch (const Error& e) {
      throw Error(name + ": " + e.what());
    }
  }
  if (doc.contains("lights")) {
    const json& lights = doc["lights"];
    if (!lights.is_array())
      throw Error(name + ": top level: 'lights' must be an array of light objects (got " + shown(lights) + ")");
    for (std::size_t i = 0; i < lights.size(); ++i) {
      file.lights.push_back(parse_light(lights[i], KeyReader{name + ": light " + std::to_string(i) + ": "}));
      try {
        validate(file.lights.back(), i);  // "light I: KEY RULE (got V)"
      } catch (const Error& e) {
        throw Error(name + ": " + e.what());
      }
    }
  }
  return file;
}

std::vector<FogVolume> parse_volumes_json(const std::string& text, const std::string& name) {
  return volumes_alone(parse_volumes_file(text, name), name);
}

VolumesFile read_volumes_file(const std::string& path) {
  // Opened without blocking (a FIFO would wait for a writer) and checked before a byte is read:
  // /dev/zero or a huge file must not grow the text until memory runs out.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw Error(path + ": cannot open the volumes file (--volumes)");
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw Error(path + ": read error (--volumes): " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw Error(path + ": the volumes file (--volumes) is " + detail::non_regular_kind(path) + ", not a regular file");
  const std::string limit = std::to_string(kMaxVolumesJsonBytes) + " bytes (" +
                            std::to_string(kMaxVolumesJsonBytes >> 20) + " MiB)";
  if (std::uint64_t(st.st_size) > kMaxVolumesJsonBytes)
    throw Error(path + ": the volumes file (--volumes) is " + std::to_string(st.st_size) + " bytes, more than the " +
                limit + " a VOLUMES.json may be");
  std::string text(std::size_t(st.st_size), '\0');
  std::size_t got = 0;
  for (;;) {  // to the end, which may have moved since fstat: never past the limit
    if (got == text.size()) {
      if (text.size() >= kMaxVolumesJsonBytes) {
        char probe;
        const ssize_t more = ::read(fd, &probe, 1);
        if (more > 0)
          throw Error(path + ": the volumes file (--volumes) grew past the " + limit + " a VOLUMES.json may be while "
                      "it was read");
        if (more == 0) break;
        if (errno == EINTR) continue;
        throw Error(path + ": read error (--volumes): " + std::strerror(errno));
      }
      text.resize(std::min<std::size_t>(kMaxVolumesJsonBytes, text.size() + 4096));
    }
    const ssize_t n = ::read(fd, text.data() + got, text.size() - got);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw Error(path + ": read error (--volumes): " + std::strerror(errno));
    }
    got += std::size_t(n);
  }
  text.resize(got);
  return parse_volumes_file(text, path);
}

std::vector<FogVolume> read_volumes_json(const std::string& path) { return volumes_alone(read_volumes_file(path), path); }

namespace {
// The shortest decimal that reads back as f ("0.45", not the double 0.44999998807907104).
double shortest(float f) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, f);
  return std::strtod(std::string(buf, r.ptr).c_str(), nullptr);
}
}  // namespace

std::string volumes_to_json(const std::vector<FogVolume>& volumes) { return volumes_to_json(volumes, {}); }

std::string volumes_to_json(const VolumesFile& file) { return volumes_to_json(file.volumes, file.lights); }

std::string volumes_to_json(const std::vector<FogVolume>& volumes, const std::vector<LocalLight>& lights) {
  const auto v3 = [](const glm::vec3& a) { return json::array({shortest(a.x), shortest(a.y), shortest(a.z)}); };
  json list = json::array();
  for (const FogVolume& v : volumes) {
    json j = json::object();
    for (const auto& [key, member] : volume_fields())
      std::visit(
          [&, key = key](auto m) {
            using T = std::remove_cv_t<std::remove_reference_t<decltype(v.*m)>>;
            const auto v3 = [](const glm::vec3& a) {
              return json::array({shortest(a.x), shortest(a.y), shortest(a.z)});
            };
            if constexpr (std::is_same_v<T, float>) j[key] = shortest(v.*m);
            if constexpr (std::is_same_v<T, bool>) j[key] = v.*m;
            if constexpr (std::is_same_v<T, glm::vec3>) j[key] = v3(v.*m);
            if constexpr (std::is_same_v<T, glm::vec4>)
              j[key] = json::array({shortest((v.*m).r), shortest((v.*m).g), shortest((v.*m).b), shortest((v.*m).a)});
            if constexpr (std::is_same_v<T, std::optional<glm::vec3>>)
              if (v.*m) j[key] = v3(*(v.*m));
          },
          member);
    list.push_back(j);
  }
  json doc{{"volumes", list}};
  if (!lights.empty()) {
    json out = json::array();
    for (const LocalLight& l : lights) {
      json j{{"type", to_string(l.kind)}};
      for (const auto& [key, member] : light_fields()) {
        if (l.kind == LightKind::point && spot_only(key)) continue;
        std::visit(
            [&, key = key](auto m) {
              using T = std::remove_cv_t<std::remove_reference_t<decltype(l.*m)>>;
              if constexpr (std::is_same_v<T, float>) j[key] = shortest(l.*m);
              if constexpr (std::is_same_v<T, glm::vec3>) j[key] = v3(l.*m);
            },
            member);
      }
      out.push_back(j);
    }
    doc["lights"] = out;
  }
  return doc.dump(2) + "\n";
}

}  // namespace fogcl
