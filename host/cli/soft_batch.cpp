// `soft --frames LIST`: soft shadows of a sequence of frames on one warm device (programs built
// once), decoding the next frame and encoding the last one on threads while the device runs the
// current one (batch_runner.hpp). Each map's light comes from its header, as in a single run.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>

#include "batch_runner.hpp"
#include "frame_list.hpp"
#include "image_io.hpp"
#include "depth_inputs.hpp"
#include "options_soft.hpp"
#include "print.hpp"
#include "verbose.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/runtime.hpp"

namespace sf::cli {
int run_soft_batch(const SoftArgs& a) {
  if (!a.lights.empty() || !a.shadow_map.empty() || !a.receivers.empty() || !a.receiver_depth.empty())
    throw InputError("--frames replaces --shadow-map, --receivers, --receiver-depth and --lights");
  if (!a.inputs.camera.empty() || !a.inputs.camera_depth.empty())
    throw InputError("--frames names each frame's camera on its line (camera= camera-depth=), not --camera");
  validate_depth_args(a.inputs);
  const SoftOptions opt = soft_options(a);
  const Shard shard = a.shard.empty() ? Shard{} : parse_shard(a.shard);
  std::vector<FrameSpec> frames = read_frame_list(a.frames);
  check_batch_outputs(frames, {}, a.frames);  // the whole list's: every shard refuses what one run refuses
  frames = shard_frames(frames, shard);
  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  StageTimes device;
  size_t receivers_done = 0;

  BatchSettings settings;
  settings.keep_going = a.keep_going;
  settings.progress = !a.quiet && stderr_is_terminal();
  struct Loaded {
    std::vector<SoftLightInput> light;
    std::vector<std::string> warnings;  // printed once the frame is written
  };
  struct Done {
    HostImage visibility;
    std::vector<std::string> warnings;
  };
  const BatchReport report = run_batch<Loaded, Done>(
      frames, settings,
      [&](const FrameSpec& f) {
        const FrameFiles files{f.shadow_map, f.receivers,    f.receiver_depth,
                               f.camera,     f.camera_depth, f.light.empty() ? a.inputs.light : f.light};
        Loaded loaded;
        loaded.light.push_back(load_soft_frame(files, a, &loaded.warnings));
        return loaded;
      },
      [&](const FrameSpec&, Loaded& loaded) {
        std::vector<SoftLightInput>& light = loaded.light;
        // One light through what a single run calls: the same bytes.
        SoftOptions o = opt;
        o.light = light.front().light;
        validate(o);
        SoftResult r = soft_filter_lights(runtime, o, light);
        device += r.times;
        receivers_done += light.front().receivers.count();
        return Done{std::move(r.visibility), std::move(loaded.warnings)};
      },
      [&](const FrameSpec& f, const Done& done) {
        io::write_image(f.output, done.visibility);
        print_warnings(done.warnings, f.where);
      });

  if (!a.quiet) {
    const double per_frame = 1e3 / double(std::max<size_t>(report.frames - report.failed, 1));
    std::cout << formatted(
        "shadowfilter soft: batch of %zu frames, %zu written, %zu failed | %s | device %s | device ms per frame: "
        "transform %.3f, mips %.3f, sat %.3f, reconstruct %.3f | stage s in all: decode %.2f, run %.2f, encode %.2f "
        "(decode and encode overlap the run) | wall %.2f s, %.1f frames/s, %.1f Mreceivers/s\n",
        report.frames, report.written, report.failed, soft_method_name(opt.method), runtime->info().device_name.c_str(),
        device.transform * per_frame, device.pyramid * per_frame, device.sat * per_frame,
        device.reconstruct * per_frame, report.decode, report.process, report.encode, report.wall,
        report.written / std::max(report.wall, 1e-9), receivers_done / std::max(report.wall, 1e-9) * 1e-6);
  }
  return static_cast<int>(std::min<size_t>(report.failed, 125));
}

}  // namespace sf::cli
