#pragma once
// The frames of a batch (`filter --frames LIST`, `--shadow-map A B ... --output-dir DIR`):
// what each reads and writes, and where a message about it points.
#include <cstddef>
#include <istream>
#include <string>
#include <vector>

namespace sf::cli {

struct FrameSpec {
  std::string where;  // "LIST:LINE" for a list's frame, the map's path for --output-dir frames
  std::string shadow_map, receivers, receiver_depth, output;  // one of receivers, receiver_depth or camera
  std::string camera, camera_depth;                           // receivers from a camera (camera= camera-depth=)
  std::string light;                                          // the frame's light (light=), else the command's --light
};

// The most frames a list may hold (an hour at 24 frames a second is 86,400).
inline constexpr size_t kMaxFrames = 100000;

// A frame list: one frame a line,
//   SHADOWMAP RECEIVERS OUTPUT
//   SHADOWMAP depth=RECEIVER_DEPTH OUTPUT
//   SHADOWMAP camera=CAMERA.json camera-depth=CAMERA_DEPTH OUTPUT
// each optionally with light=LIGHT.json before OUTPUT; fields separated by blanks (a field with
// blanks in double quotes), paths relative to the list's directory; blank lines and text after
// '#' are ignored. Lines are at most kMaxListLineBytes (list_lines.hpp), frames at most
// kMaxFrames. InputError naming the line for any other line, and for a list without frames; the
// list must be a regular file (io::require_regular_file).
std::vector<FrameSpec> read_frame_list(const std::string& list);
// The same from text already open; `list` names it in messages and gives the paths' directory.
std::vector<FrameSpec> parse_frame_list(std::istream& in, const std::string& list);

// One frame per map, sharing one receiver file: the output is DIR/<map's stem><extension>.
std::vector<FrameSpec> frames_of_maps(const std::vector<std::string>& maps, const std::string& receivers,
                                      const std::string& receiver_depth, const std::string& output_dir,
                                      const std::string& extension);

// One of N parts of a batch (`--shard K/N`): frames i with i mod N = K - 1, so that any scheduler
// (Slurm job arrays, GNU parallel, Kubernetes jobs) runs a sequence as N independent processes
// and the union of their outputs is the unsharded run's, byte for byte (frames are independent).
// Round robin rather than N blocks: frames late in a sequence often cost more than early ones.
struct Shard {
  size_t index = 0;  // K - 1
  size_t count = 1;  // N
};
// "K/N" with 1 <= K <= N <= kMaxFrames; InputError naming --shard otherwise.
Shard parse_shard(const std::string& text);
// The frames of `shard`, in list order (none when the list has fewer frames than K).
std::vector<FrameSpec> shard_frames(const std::vector<FrameSpec>& frames, const Shard& shard);

// Refuses a batch (InputError) where two frames write one file or a frame's output (or its
// `extra` outputs, e.g. the preview) is any frame's input or the list itself (`list`, "" for
// none): checked before any frame runs.
void check_batch_outputs(const std::vector<FrameSpec>& frames,
                         const std::vector<std::vector<std::string>>& extra_outputs, const std::string& list);

}  // namespace sf::cli
