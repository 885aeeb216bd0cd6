#pragma once
// The OpenEXR header walked before OpenEXR reads it (internal to host/io). OpenEXR allocates what
// a header declares as it parses it (a string attribute of 2 GB, offset tables and line buffers
// for any data window) before anything else can look at the sizes, so read_raw checks them first.
#include <cstdint>
#include <string>

namespace sf::io::detail {

// Walks every header of an OpenEXR file (one, or each part of a multi-part file) without
// allocating what it declares. InputError("<role> '<path>': ...") when an attribute's declared
// size runs past the end of the file, a name runs on without its terminating NUL, the header
// ends early, a data window is empty or inverted, its pixels as float exceed the memory budget
// (input_file.hpp), or the file is too small for the chunk offset table the data window and
// tiling need (8 bytes a chunk).
void check_exr_header(const std::string& path, uint64_t file_bytes, const std::string& role);

}  // namespace sf::io::detail
