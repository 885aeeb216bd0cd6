#pragma once
// The header of a PLY file, checked against the PLY grammar before assimp reads the file: assimp
// 5.2's PLY reader loops for ever on headers it does not expect (one without end_header, an
// end_header line with a character before it), so only well-formed headers reach it.
#include <string>

namespace sf::scene {

// True when assimp would read the file as PLY: its name ends in .ply, or it starts with "ply"
// (assimp's signature check, any case).
bool looks_like_ply(const std::string& path);

// InputError("<role> '<path>': PLY header line N: ...") unless the header is, line by line (LF or
// CR LF): "ply"; "format ascii|binary_little_endian|binary_big_endian VERSION"; then "comment
// ...", "obj_info ...", "element NAME COUNT" and, after an element, "property TYPE NAME" or
// "property list TYPE TYPE NAME" (TYPE one of PLY's scalar types); ending with "end_header",
// all within the first 1 MiB of the file.
void check_ply_header(const std::string& path, const std::string& role);

}  // namespace sf::scene
