#include "output_file.hpp"

#include <sys/stat.h>

#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <system_error>

#include "atomic_file.hpp"
#include "io_detail.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::io {
namespace {

namespace fs = std::filesystem;

struct InputRegistry {
  std::mutex mutex;
  bool on = false;
  std::map<std::string, std::string> files;  // identity -> the path it was read by
};

InputRegistry& inputs_read() {
  static InputRegistry registry;
  return registry;
}

// The path an existing input was read by, or "" when `path` is not an input of this process.
std::string input_named(const std::string& identity) {
  InputRegistry& r = inputs_read();
  std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = r.files.find(identity);
  return it == r.files.end() ? "" : it->second;
}

void refuse_if_input(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;  // not there yet: not an input
  const std::string read_as = input_named(file_identity(path));
  if (!read_as.empty())
    throw InputError("output '" + detail::one_line(path) + "' is the input '" + detail::one_line(read_as) +
                     "'; refusing to overwrite an input");
}

std::unique_ptr<sf::detail::StagedFile> stage(const std::string& path, const std::string& role, const void* data,
                                              size_t size) {
  refuse_if_input(path);
  try {
    return std::make_unique<sf::detail::StagedFile>(path, data, size);
  } catch (const sf::detail::FileWriteError& e) {
    detail::fail(role, path, e.what());
  }
}

void commit_staged(sf::detail::StagedFile& file, const std::string& path, const std::string& role) {
  refuse_if_input(path);  // an input read while the file was staged
  try {
    file.commit();
  } catch (const sf::detail::FileWriteError& e) {
    detail::fail(role, path, e.what());
  }
}

}  // namespace

void write_file(const std::string& path, const std::string& role, const void* data, size_t size) {
  auto staged = stage(path, role, data, size);
  commit_staged(*staged, path, role);
}

void write_text(const std::string& path, const std::string& role, const std::string& text) {
  write_file(path, role, text.data(), text.size());
}

struct OutputSet::Staged {
  std::string path, role;
  std::unique_ptr<sf::detail::StagedFile> file;
};

OutputSet::OutputSet() = default;
OutputSet::~OutputSet() = default;

void OutputSet::add(const std::string& path, const std::string& role, const void* data, size_t size) {
  for (const auto& f : files_)
    if (file_identity(f->path) == file_identity(path))
      throw InputError("output '" + detail::one_line(path) + "' is written twice by one run");
  files_.push_back(std::make_unique<Staged>(Staged{path, role, stage(path, role, data, size)}));
}

void OutputSet::commit() {
  for (auto& f : files_) commit_staged(*f->file, f->path, f->role);
  files_.clear();
}

std::string file_identity(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return "path " + (ec ? fs::absolute(path).lexically_normal().string() : resolved.string());
}

void record_input(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;  // the reader reports a missing file itself
  InputRegistry& r = inputs_read();
  std::lock_guard<std::mutex> lock(r.mutex);
  if (r.on) r.files.emplace(file_identity(path), path);
}

void guard_inputs_read(bool on) {
  InputRegistry& r = inputs_read();
  std::lock_guard<std::mutex> lock(r.mutex);
  r.on = on;
  if (!on) r.files.clear();
}

void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  std::map<std::string, std::string> in;
  for (const std::string& path : inputs)
    if (!path.empty()) in.emplace(file_identity(path), path);
  std::set<std::string> seen;
  for (const std::string& out : outputs) {
    if (out.empty()) continue;
    const std::string id = file_identity(out);
    const auto it = in.find(id);
    if (it != in.end())
      throw InputError("output '" + detail::one_line(out) + "' is the input '" + detail::one_line(it->second) +
                       "'; refusing to overwrite an input");
    if (!seen.insert(id).second)
      throw InputError("output '" + detail::one_line(out) + "' is named twice; each output needs its own file");
    refuse_if_input(out);
  }
}

size_t remove_unfinished_outputs_before_exit() noexcept {
  return sf::detail::remove_unfinished_files(sf::detail::AfterRemoval::Ending);
}

void mark_unfinished_directory(const std::string& path) { sf::detail::register_unfinished(path); }
void unmark_unfinished_directory(const std::string& path) { sf::detail::unregister_unfinished(path); }

}  // namespace sf::io
