#include "frame_list.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "input_file.hpp"
#include "list_lines.hpp"
#include "shadowfilter/errors.hpp"
#include "output_file.hpp"

namespace sf::cli {
namespace {

namespace fs = std::filesystem;

// The fields of one line: blank-separated, "..." keeps blanks, '#' outside quotes ends the line.
std::vector<std::string> split_fields(const std::string& line, const std::string& where) {
  std::vector<std::string> fields;
  size_t i = 0;
  while (i < line.size()) {
    const char c = line[i];
    if (c == ' ' || c == '\t' || c == '\r') {
      ++i;
    } else if (c == '#') {
      break;
    } else if (c == '"') {
      const size_t end = line.find('"', i + 1);
      if (end == std::string::npos) throw InputError(where + ": a quote is not closed");
      fields.push_back(line.substr(i + 1, end - i - 1));
      i = end + 1;
    } else {
      size_t end = i;
      while (end < line.size() && line[end] != ' ' && line[end] != '\t' && line[end] != '\r' && line[end] != '#') ++end;
      fields.push_back(line.substr(i, end - i));
      i = end;
    }
  }
  return fields;
}

std::string relative_to(const fs::path& dir, const std::string& path) {
  const fs::path p(path);
  return p.is_absolute() ? p.string() : (dir / p).lexically_normal().string();
}

// One key per file whatever the spelling of its path (io::file_identity).
std::string file_key(const std::string& path) { return io::file_identity(path); }

// The value of a "key=value" field, or false when the field has another key.
bool keyed(const std::string& field, const std::string& key, const std::string& where, std::string* value) {
  if (field.compare(0, key.size() + 1, key + "=") != 0) return false;
  if (field.size() == key.size() + 1) throw InputError(where + ": '" + key + "=' names no file");
  *value = field.substr(key.size() + 1);
  return true;
}

// The fields of one frame: SHADOWMAP, the receivers' fields, [light=LIGHT], OUTPUT.
bool read_frame_fields(std::vector<std::string> f, const fs::path& dir, FrameSpec* frame) {
  if (f.size() < 3) return false;
  std::string value;
  if (keyed(f[f.size() - 2], "light", frame->where, &value)) {
    frame->light = relative_to(dir, value);
    f.erase(f.end() - 2);
  }
  frame->shadow_map = relative_to(dir, f.front());
  frame->output = relative_to(dir, f.back());
  if (f.size() == 4) {
    std::string camera, depth;
    if (!keyed(f[1], "camera", frame->where, &camera) || !keyed(f[2], "camera-depth", frame->where, &depth))
      return false;
    frame->camera = relative_to(dir, camera);
    frame->camera_depth = relative_to(dir, depth);
    return true;
  }
  if (f.size() != 3) return false;
  if (keyed(f[1], "depth", frame->where, &value))
    frame->receiver_depth = relative_to(dir, value);
  else if (f[1].compare(0, 7, "camera=") == 0)  // a camera needs its depth buffer too
    return false;
  else
    frame->receivers = relative_to(dir, f[1]);
  return true;
}

}  // namespace

std::vector<FrameSpec> read_frame_list(const std::string& list) {
  io::require_regular_file(list, "frame list");
  io::record_input(list);
  std::ifstream in(list, std::ios::binary);
  if (!in) throw InputError("frame list '" + list + "': cannot open it");
  return io::with_out_of_memory_named(list, "frame list", [&] { return parse_frame_list(in, list); });
}

std::vector<FrameSpec> parse_frame_list(std::istream& in, const std::string& list) {
  const fs::path dir = fs::path(list).parent_path();
  std::vector<FrameSpec> frames;
  ListLines lines(in, list);
  std::string line;
  while (lines.next(line)) {
    const std::string where = lines.where();
    const std::vector<std::string> f = split_fields(line, where);
    if (f.empty()) continue;
    if (frames.size() == kMaxFrames)
      throw InputError(where + ": more than " + std::to_string(kMaxFrames) + " frames; a list holds at most " +
                       std::to_string(kMaxFrames));
    FrameSpec frame;
    frame.where = where;
    if (!read_frame_fields(f, dir, &frame))
      throw InputError(where +
                       ": expected 'SHADOWMAP RECEIVERS OUTPUT', 'SHADOWMAP depth=RECEIVER_DEPTH OUTPUT' or "
                       "'SHADOWMAP camera=CAMERA.json camera-depth=DEPTH OUTPUT' (each with an optional "
                       "light=LIGHT.json before OUTPUT), got " +
                       std::to_string(f.size()) + " fields");
    frames.push_back(std::move(frame));
  }
  if (frames.empty()) throw InputError("frame list '" + list + "' holds no frames");
  return frames;
}

std::vector<FrameSpec> frames_of_maps(const std::vector<std::string>& maps, const std::string& receivers,
                                      const std::string& receiver_depth, const std::string& output_dir,
                                      const std::string& extension) {
  std::vector<FrameSpec> frames;
  for (const std::string& map : maps) {
    FrameSpec frame;
    frame.where = map;
    frame.shadow_map = map;
    frame.receivers = receivers;
    frame.receiver_depth = receiver_depth;
    frame.output = (fs::path(output_dir) / (fs::path(map).stem().string() + extension)).string();
    frames.push_back(std::move(frame));
  }
  return frames;
}

void check_batch_outputs(const std::vector<FrameSpec>& frames,
                         const std::vector<std::vector<std::string>>& extra_outputs, const std::string& list) {
  std::map<std::string, std::string> inputs;  // file -> the first frame reading it
  if (!list.empty()) inputs.emplace(file_key(list), "the frame list");
  for (const FrameSpec& f : frames)
    for (const std::string* in : {&f.shadow_map, &f.receivers, &f.receiver_depth, &f.camera, &f.camera_depth, &f.light})
      if (!in->empty()) inputs.emplace(file_key(*in), f.where);
  std::map<std::string, std::string> outputs;  // file -> the frame writing it
  for (size_t i = 0; i < frames.size(); ++i) {
    std::vector<std::string> written{frames[i].output};
    if (i < extra_outputs.size()) written.insert(written.end(), extra_outputs[i].begin(), extra_outputs[i].end());
    for (const std::string& out : written) {
      const std::string key = file_key(out);
      if (const auto in = inputs.find(key); in != inputs.end())
        throw InputError(frames[i].where + ": output '" + out + "' is an input of " + in->second +
                         "; refusing to overwrite an input");
      if (const auto [at, added] = outputs.emplace(key, frames[i].where); !added)
        throw InputError(frames[i].where + ": output '" + out + "' is written by " + at->second + " too");
    }
  }
}

Shard parse_shard(const std::string& text) {
  const auto refuse = [&text] {
    return InputError("--shard must be K/N with 1 <= K <= N <= " + std::to_string(kMaxFrames) + ", got '" + text + "'");
  };
  const size_t slash = text.find('/');
  if (slash == std::string::npos) throw refuse();
  const auto whole = [&refuse](const std::string& s) {
    if (s.empty() || s.size() > 6 || s.find_first_not_of("0123456789") != std::string::npos) throw refuse();
    return static_cast<size_t>(std::stoul(s));
  };
  const size_t k = whole(text.substr(0, slash)), n = whole(text.substr(slash + 1));
  if (k < 1 || n < 1 || k > n || n > kMaxFrames) throw refuse();
  return Shard{k - 1, n};
}

std::vector<FrameSpec> shard_frames(const std::vector<FrameSpec>& frames, const Shard& shard) {
  std::vector<FrameSpec> out;
  for (size_t i = shard.index; i < frames.size(); i += shard.count) out.push_back(frames[i]);
  return out;
}

}  // namespace sf::cli
