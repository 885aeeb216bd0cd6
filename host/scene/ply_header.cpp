#include "ply_header.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "io_detail.hpp"

namespace sf::scene {
namespace {

using io::detail::fail;

constexpr size_t kMaxHeaderBytes = size_t(1) << 20;

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return text;
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

bool is_scalar_type(const std::string& type) {
  static const char* const kTypes[] = {"char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
                                       "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  return std::find(std::begin(kTypes), std::end(kTypes), type) != std::end(kTypes);
}

bool is_count(const std::string& text) {
  return !text.empty() && text.size() <= 10 && text.find_first_not_of("0123456789") == std::string::npos;
}

}  // namespace

bool looks_like_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[3] = {0, 0, 0};
  in.read(head, 3);
  return lower(std::filesystem::path(path).extension().string()) == ".ply" ||
         (in.gcount() == 3 && lower(std::string(head, 3)) == "ply");
}

void check_ply_header(const std::string& path, const std::string& role) {
  std::ifstream in(path, std::ios::binary);
  std::string text(kMaxHeaderBytes, '\0');
  in.read(text.data(), std::streamsize(text.size()));
  text.resize(size_t(in.gcount()));
  bool has_element = false;
  size_t at = 0;
  for (int number = 1;; ++number) {
    const size_t end = text.find('\n', at);
    const auto problem = [&](const std::string& what) {
      fail(role, path, "PLY header line " + std::to_string(number) + ": " + what);
    };
    if (end == std::string::npos)
      problem("no end_header within the first " + std::to_string(kMaxHeaderBytes) + " bytes");
    std::string line = text.substr(at, end - at);
    at = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string> w = words(line);
    std::string shown = line.substr(0, 60);
    for (char& c : shown)
      if (!std::isprint(static_cast<unsigned char>(c))) c = '?';
    shown = "'" + shown + "'";
    if (number == 1) {
      if (line != "ply") problem("expected 'ply', found " + shown);
      continue;
    }
    if (number == 2) {
      if (w.size() != 3 || w[0] != "format" ||
          (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
        problem("expected 'format ascii|binary_little_endian|binary_big_endian VERSION', found " + shown);
      continue;
    }
    if (w.empty()) problem("an empty line");
    if (line.compare(0, w[0].size(), w[0]) != 0) problem("blanks before " + shown);
    if (w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      if (w.size() != 1) problem("expected 'end_header' alone, found " + shown);
      return;
    }
    if (w[0] == "element") {
      if (w.size() != 3 || !is_count(w[2])) problem("expected 'element NAME COUNT', found " + shown);
      has_element = true;
      continue;
    }
    if (w[0] == "property") {
      if (!has_element) problem("a property before any element");
      const bool scalar = w.size() == 3 && is_scalar_type(w[1]);
      const bool list = w.size() == 5 && w[1] == "list" && is_scalar_type(w[2]) && is_scalar_type(w[3]);
      if (!scalar && !list) problem("expected 'property TYPE NAME' or 'property list TYPE TYPE NAME', found " + shown);
      continue;
    }
    problem("unexpected " + shown);
  }
}

}  // namespace sf::scene
