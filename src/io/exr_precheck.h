// A walk over the EXR header bytes before OpenEXR parses them (src/io only). OpenEXR 3.1 trusts
// the sizes a header states: a corrupt attribute size or data window makes it allocate gigabytes
// before it notices the file is short. This check rejects, from the bytes alone, any attribute
// larger than the rest of the file and any part whose chunk offset table (8 bytes per chunk,
// stored in the file) could not fit in it, or whose data or display window exceeds max_pixels.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace fogcl::detail {

// read(offset, n, dst) copies n bytes at offset (the caller checks bounds against file_size).
// Throws fogcl::Error "NAME: cannot read EXR: why".
void precheck_exr_header(const std::string& name, std::uint64_t file_size, std::int64_t max_pixels,
                         const std::function<void(std::uint64_t offset, std::size_t n, char* dst)>& read);

}  // namespace fogcl::detail
