// Python keyword options -> `fogcl apply`'s options (docs/python.md, "Options"): each keyword is
// the flag with dashes as underscores, its value written as the flag's text, then parsed and
// resolved by the command line's own code (cli/apply_flags.h): the same words, rules and messages.
#pragma once

#include <string>
#include <vector>

#include <pybind11/pybind11.h>

#include "cli/cli.h"

namespace fogcl::python {

// The flags of `options` as a command line: near=0.3 -> "--near", "0.3"; True -> the flag alone,
// False or None -> left out; a tuple or list -> "a,b,c"; a number as Python's repr (which reads
// back to the same double); volumes= a dict or list -> the document (ApplyOptions' volumes_text).
// Throws pybind11::value_error for a value of no flag's kind.
std::vector<std::string> option_args(const pybind11::dict& options, std::string* volumes_text);

// `options` parsed and resolved as `fogcl apply --near ... --mode ...` is, for a frame in memory
// (no file flags). Throws pybind11::value_error with the command line's message.
cli::ApplyOptions apply_options(const pybind11::dict& options);

// What decides the passes `options` make (o: those options parsed): the flags as typed, the
// volumes= document, and the size and time of the files they name (VOLUMES.json, the shadow
// map), so that what is kept for the next frames (fogcl.apply's devices, a VolumePass's stage)
// is not reused once a file is rewritten.
std::string options_key(const pybind11::dict& options, const cli::ApplyOptions& o);

}  // namespace fogcl::python
