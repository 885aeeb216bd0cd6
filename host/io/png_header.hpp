#pragma once
// The PNG chunk list walked before libpng reads it (internal to host/io). libpng allocates a
// chunk's declared length before it reads the chunk (a text chunk declaring 1.8 GB in a file of
// 400 bytes took 1.9 GB and failed at the end of the file), so read_raw checks every length
// against the bytes the file holds first, as it does OpenEXR's header (exr_header.hpp).
#include <cstdint>
#include <string>

namespace sf::io::detail {

// Walks the chunks from the signature to IEND without reading their data. InputError("<role>
// '<path>': ...") when a chunk's length is over 2^31 - 1 (the PNG limit) or runs past the end of
// the file, or the file ends before IEND.
void check_png_chunks(const std::string& path, uint64_t file_bytes, const std::string& role);

}  // namespace sf::io::detail
