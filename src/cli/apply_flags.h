// `fogcl apply`'s flags: registered on a CLI11 command and resolved into ApplyOptions after
// parsing. Shared by the command line (main.cpp) and the Python module (src/python/options.h),
// so both take the same words under the same rules, with the same messages.
#pragma once

#include <string>
#include <vector>

#include "cli/cli.h"

namespace CLI {
class App;
class ParseError;
}  // namespace CLI

namespace fogcl::cli {

// What the flags fill: the options, and the keyword flags kept as text until they are resolved.
struct ApplyFlags {
  ApplyOptions options;
  std::string mode = "exp2", precision = "precise", fog_color, sky = "far";
};

// Registers the flags on `apply`. files = false leaves out the flags that name files or their
// formats (--color, --depth, --out, --png, --layer, --depth-channel, --rgba-only, --frames,
// --keep-going, --threads, --pixel-type, --compression, --verbose), for a frame held in memory.
void add_apply_flags(CLI::App& apply, ApplyFlags& flags, bool files = true);

// After a successful parse: the rules the flags make together (--far > --near, ...), the keyword
// flags into settings, and the camera, volume and height flags resolved. Throws UsageError (a flag
// missing: exit 2) or fogcl::Error (a rule broken: exit 1), each one line naming the flags.
void resolve_apply_flags(const CLI::App& apply, ApplyFlags& flags);

// A CLI11 parse error as one line: *rule tells a broken rule (exit 1) from a malformed command
// line (exit 2, "(see --help)"). An unknown option left on one of `commands` is named first.
std::string parse_error_text(const CLI::ParseError& e, const std::vector<const CLI::App*>& commands, bool* rule);

// The flags of a frame in memory (files = false), parsed and resolved as `fogcl apply` does:
// `args` as on a command line ("--near", "0.3", "--distance", ...). Throws UsageError or
// fogcl::Error with the command line's message.
ApplyOptions parse_memory_apply_args(const std::vector<std::string>& args);

}  // namespace fogcl::cli
