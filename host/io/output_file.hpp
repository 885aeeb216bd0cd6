#pragma once
// Every output of every command goes through here: images, previews, .csm files, result tables,
// plots, scene descriptions. A file is written whole to a temporary file beside its destination,
// every write and the close checked, synced to disk and renamed last (detail::StagedFile); a
// failure is an InputError naming the file and the reason (exit 2), and leaves an earlier file at
// the destination as it was.
//
// No output may replace an input: the readers record each file they open (record_input), and a
// write whose destination is one of them is refused, whatever path reaches it (symbolic links,
// hard links, "..", symlinked directories). Commands also check their declared inputs and outputs
// before they start (check_outputs), so that a run that would end in that refusal does not start.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace sf::io {

// Writes `size` bytes as the file `path`; `role` names it in messages ("output image").
void write_file(const std::string& path, const std::string& role, const void* data, size_t size);
void write_text(const std::string& path, const std::string& role, const std::string& text);

// Files that appear together or not at all (a visibility with its preview and flags): each is
// staged as it is added, and commit() moves them all into place. Without commit() (an error on
// the way) none of them appears.
class OutputSet {
 public:
  OutputSet();
  ~OutputSet();
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  void add(const std::string& path, const std::string& role, const void* data, size_t size);
  void commit();

 private:
  struct Staged;
  std::vector<std::unique_ptr<Staged>> files_;
};

// The identity of a file whatever the path that names it: device and inode where it exists, else
// the absolute path with its existing directories resolved (an output not written yet).
std::string file_identity(const std::string& path);

// Records `path` as an input of this process (the readers call it as they open a file) while
// the guard is on. The CLI turns it on for the whole process; a program that uses the library
// (a test, a script that rewrites a file it read) leaves it off.
void record_input(const std::string& path);
void guard_inputs_read(bool on);

// InputError when an output is one of the inputs (or of the files read so far), or two outputs are
// one file. Inputs that are empty strings are skipped.
void check_outputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs);

// Removes the temporary files and partial directories of unfinished writes and returns how many
// it removed. For the CLI's signal watcher, before the process ends: no write starts afterwards
// (one that tries waits for the end of the process).
size_t remove_unfinished_outputs_before_exit() noexcept;

// A directory that is being filled (a scene's staging directory): removed with its contents if the
// process is interrupted before unmark_unfinished_directory.
void mark_unfinished_directory(const std::string& path);
void unmark_unfinished_directory(const std::string& path);

}  // namespace sf::io
