#pragma once
// What `filter`, `soft` and `receivers` read and how (docs/inputs.md): the map's depth encoding
// (stated, or from a light's projection), the receivers' own encoding when it differs, and
// receivers made in memory from a camera. One frame's inputs are loaded here for single runs
// and batches alike.
#include <CLI/CLI.hpp>

#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "camera_io.hpp"
#include "image_io.hpp"
#include "shadowfilter/host_image.hpp"

namespace sf::cli {

struct DepthInputArgs {
  std::string encoding;           // --encoding; "" = linear (or the light's window depth with --light)
  std::string receiver_encoding;  // --receiver-encoding; "" = the map's
  double near_plane = std::numeric_limits<double>::quiet_NaN();             // --near; NaN: not given
  double far_plane = std::numeric_limits<double>::quiet_NaN();              // --far
  std::string beyond_far = "error";                                         // --beyond-far error|far
  std::string nonfinite = "error";                                          // --nonfinite error|far
  std::string light;                                                        // --light LIGHT.json
  std::string camera, camera_depth, camera_depth_kind = "window", normals;  // --camera ... (receivers in memory)
};

// --encoding, --receiver-encoding, --near, --far, --beyond-far, --nonfinite and --light.
void add_depth_options(CLI::App& cmd, DepthInputArgs& args);
// --camera, --camera-depth, --camera-depth-kind, --normals (with --light: receivers from a camera).
void add_camera_options(CLI::App& cmd, DepthInputArgs& args);

// The files one frame reads: a map and one of receivers, receiver_depth or camera + camera_depth;
// `light` (per frame, or the command's --light) may be empty.
struct FrameFiles {
  std::string shadow_map, receivers, receiver_depth, camera, camera_depth, light;
};
// InputError unless the frame names exactly one source of receivers, and a camera comes with its
// depth buffer and a light.
void require_one_receiver_source(const FrameFiles& files);

struct FrameInputs {
  HostImage depth;
  Receivers receivers;
  // Warnings about inputs that were likely misread (the results are still written): each one
  // line, without the "shadowfilter: warning: " prefix.
  std::vector<std::string> warnings;
};

// The map's decoding: --encoding / --near / --far, or the light's projection (then --encoding
// may only say linear: the map in world units along the light's axis; --near/--far are refused).
io::DepthLoadOptions map_decoding(const DepthInputArgs& args, const std::optional<io::ViewFile>& light,
                                  const std::string& light_path);
// The receivers' own decoding when --receiver-encoding states one.
std::optional<io::DepthLoadOptions> stated_receiver_decoding(const DepthInputArgs& args,
                                                             const io::DepthLoadOptions& map);

// Checks the options alone (before any file is read): names and combinations.
void validate_depth_args(const DepthInputArgs& args);

// The map's decoding for a frame (its light file read when it names one).
io::DepthLoadOptions frame_map_decoding(const FrameFiles& files, const DepthInputArgs& args);

// A frame's receivers without the map's fit: what a batch may reuse from the frame before.
struct LoadedReceivers {
  Receivers receivers;
  io::ReceiverHeader header;          // a receiver image's header (empty otherwise)
  std::vector<std::string> warnings;  // about the source itself (a camera mostly outside the light)
};
// From a receiver image, a receiver depth image (on the grid of `depth`) or a camera (for a map
// of `depth`'s size), decoded as `map` unless --receiver-encoding states otherwise.
LoadedReceivers load_receivers_of(const FrameFiles& files, const DepthInputArgs& args, const HostImage& depth,
                                  const io::DepthLoadOptions& map);

// Loads one frame: the map decoded as stated, its receivers, and every warning about them.
FrameInputs load_frame(const FrameFiles& files, const DepthInputArgs& args);

// The warnings of receivers against their map (receiver_fit.hpp): most receivers outside the map
// (u, v in texels?), 95% of them in front of the map's first surface or behind it (d in another
// encoding than the map's?), footprints measured for another map size, another light's planes.
// Commands print them once the results are written (a run that fails prints its error alone).
std::vector<std::string> fit_warnings(const HostImage& depth, const Receivers& receivers,
                                      const io::ReceiverHeader& header, const io::DepthLoadOptions& map);

// Prints each warning as "shadowfilter: warning: ..." on stderr.
void print_warnings(const std::vector<std::string>& warnings, const std::string& where = "");

}  // namespace sf::cli
