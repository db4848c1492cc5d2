// Files that appear complete or not at all: written under a temporary name next to the target
// and renamed onto it (same directory, hence same file system, so the rename is atomic).
#pragma once

#include <fstream>
#include <functional>
#include <string>

namespace fogcl::detail {

// `body` writes the whole file into `out`, an open binary stream on the temporary file. On success
// the temporary file is renamed onto `path`; on any failure it is removed and a fogcl::Error
// "PATH: cannot write KIND: reason" is thrown.
void write_file_atomically(const std::string& path, const char* kind,
                           const std::function<void(std::ofstream& out, const std::string& temp_path)>& body);

// Library messages may span lines; fogcl's file errors are one line.
std::string one_line(std::string s);

}  // namespace fogcl::detail
