// `filter --frames LIST` and `filter --shadow-map A B ... --output-dir DIR`: a batch of frames
// on one warm device (FrameFilter), decoding the next frame and encoding the last one on worker
// threads while the device runs the current one (batch_runner.hpp).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>

#include "batch_runner.hpp"
#include "commands.hpp"
#include "filter_options.hpp"
#include "frame_list.hpp"
#include "depth_inputs.hpp"
#include "image_io.hpp"
#include "json_summary.hpp"
#include "preview_images.hpp"
#include "print.hpp"
#include "verbose.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::cli {
namespace {

struct LoadedFrame {
  HostImage depth;
  std::shared_ptr<const LoadedReceivers> receivers;
  std::vector<std::string> warnings;  // printed once the frame is written
};

struct FilteredFrame {
  HostImage visibility;
  std::shared_ptr<const LoadedReceivers> receivers;  // for the shaded preview
  std::vector<std::string> warnings;
};

FrameFiles files_of(const FrameSpec& f, const DepthInputArgs& inputs) {
  return {f.shadow_map, f.receivers,    f.receiver_depth,
          f.camera,     f.camera_depth, f.light.empty() ? inputs.light : f.light};
}

// The receivers of the frame before, reused while frames name the same files (and, for planar
// receivers and cameras, the same map size): a sequence over one camera decodes them once. Frames
// decode on several threads (batch_runner.hpp): the lock makes the second of two frames that need
// one file wait for the first one's copy.
class ReceiverCache {
 public:
  std::shared_ptr<const LoadedReceivers> get(const FrameFiles& f, const DepthInputArgs& inputs, const HostImage& depth,
                                             const io::DepthLoadOptions& map) {
    const std::string size = std::to_string(depth.width) + "x" + std::to_string(depth.height);
    const std::string key = !f.camera.empty() ? "camera=" + f.camera + " " + f.camera_depth + " " + f.light + " " + size
                            : f.receivers.empty() ? "depth=" + f.receiver_depth + " " + size
                                                  : f.receivers;
    std::lock_guard<std::mutex> lock(mutex_);
    if (key != key_ || !receivers_) {
      receivers_.reset();
      receivers_ = std::make_shared<const LoadedReceivers>(load_receivers_of(f, inputs, depth, map));
      key_ = key;
    }
    return receivers_;
  }

 private:
  std::mutex mutex_;
  std::string key_;
  std::shared_ptr<const LoadedReceivers> receivers_;
};

}  // namespace

int run_filter_batch(const FilterArgs& a) {
  if (a.auto_args.enabled)
    throw InputError("--auto measures one input; run it on one frame and give the batch the options it chose");
  if (!a.flags_out.empty()) throw InputError("--flags-out writes one frame's mask; it does not take a batch");
  validate_depth_args(a.inputs);
  const Shard shard = a.shard.empty() ? Shard{} : parse_shard(a.shard);
  std::vector<FrameSpec> frames;
  if (!a.frames.empty()) {
    if (!a.inputs.camera.empty() || !a.inputs.camera_depth.empty())
      throw InputError("--frames names each frame's camera on its line (camera= camera-depth=), not --camera");
    frames = read_frame_list(a.frames);
  } else {
    if (a.shadow_maps.empty()) throw InputError("--output-dir needs --shadow-map A [B ...]");
    frames = frames_of_maps(a.shadow_maps, a.receivers, a.receiver_depth, a.output_dir, ".exr");
    for (FrameSpec& f : frames) f.camera = a.inputs.camera, f.camera_depth = a.inputs.camera_depth;
    require_one_receiver_source(files_of(frames.front(), a.inputs));
    std::error_code ec;
    std::filesystem::create_directories(a.output_dir, ec);
    if (ec) throw InputError("--output-dir '" + a.output_dir + "': cannot create it (" + ec.message() + ")");
  }
  const PreviewKind preview = parse_preview(a.preview);
  std::vector<std::vector<std::string>> previews(frames.size());
  for (size_t i = 0; i < frames.size(); ++i) try {
      require_one_receiver_source(files_of(frames[i], a.inputs));
      previews[i] = preview_paths(frames[i].output, preview);
    } catch (const InputError& e) {
      throw InputError(frames[i].where + ": " + e.what());
    }
  check_batch_outputs(frames, previews, a.frames);  // the whole list's: every shard refuses what one run refuses
  frames = shard_frames(frames, shard);

  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  FrameFilter filter(runtime, a.options);
  ReceiverCache receivers;
  StageTimes device;
  size_t texels = 0, receivers_done = 0;

  BatchSettings settings;
  settings.keep_going = a.keep_going;
  settings.progress = !a.quiet && stderr_is_terminal();
  const BatchReport report = run_batch<LoadedFrame, FilteredFrame>(
      frames, settings,
      [&](const FrameSpec& f) {
        const FrameFiles files = files_of(f, a.inputs);
        const io::DepthLoadOptions map = frame_map_decoding(files, a.inputs);
        LoadedFrame loaded;
        loaded.depth = io::load_depth_map(f.shadow_map, map);
        loaded.receivers = receivers.get(files, a.inputs, loaded.depth, map);
        loaded.warnings = loaded.receivers->warnings;
        const std::vector<std::string> fit =
            fit_warnings(loaded.depth, loaded.receivers->receivers, loaded.receivers->header, map);
        loaded.warnings.insert(loaded.warnings.end(), fit.begin(), fit.end());
        return loaded;
      },
      [&](const FrameSpec&, LoadedFrame& loaded) {
        const Receivers& rx = loaded.receivers->receivers;
        FilterResult r = filter.run(loaded.depth, rx);
        device += r.times;
        texels += loaded.depth.texels();
        receivers_done += rx.count();
        return FilteredFrame{std::move(r.visibility), loaded.receivers, std::move(loaded.warnings)};
      },
      [&](const FrameSpec& f, const FilteredFrame& done) {
        HostImage shaded;
        const Receivers& rx = done.receivers->receivers;
        io::write_images(output_with_previews(f.output, done.visibility, preview, rx.d, rx.ndl, &shaded));
        print_warnings(done.warnings, f.where);
      });

  if (!a.quiet && a.json) {
    const size_t ran = std::max<size_t>(report.frames - report.failed, 1);
    nlohmann::json j;
    j["command"] = "filter";
    j["filter"] = filter_options_json(a.options);
    j["batch"] = {{"frames", report.frames}, {"written", report.written}, {"failed", report.failed}};
    j["device"] = runtime->info().device_name;
    j["zero_copy"] = filter.zero_copy();
    j["allocations"] = filter.allocations();
    j["device_ms_per_frame"] = stage_ms_json(device, 1.0 / double(ran));
    j["stage_s"] = {{"decode", report.decode}, {"run", report.process}, {"encode", report.encode}};
    j["wall_s"] = report.wall;
    j["frames_per_s"] = report.written / std::max(report.wall, 1e-9);
    print_json(j);
  } else if (!a.quiet) {
    const double ms = 1e3;
    const size_t ran = std::max<size_t>(report.frames - report.failed, 1);
    std::cout << formatted(
        "shadowfilter: batch of %zu frames, %zu written, %zu failed | %s | device %s (%s, %d allocation%s) | "
        "device ms per frame: transform %.3f, blur %.3f, mips %.3f, sat %.3f, zmax %.3f, classify %.3f, "
        "reconstruct %.3f, upload %.3f, download %.3f | stage s in all: decode %.2f, run %.2f, encode %.2f "
        "(decode and encode overlap the run) | wall %.2f s, %.1f frames/s, %.1f Mtexels/s, %.1f Mreceivers/s\n",
        report.frames, report.written, report.failed,
        (method_summary(a.options) + ", " + prefilter_summary(a.options)).c_str(), runtime->info().device_name.c_str(),
        filter.zero_copy() ? "zero-copy host memory" : "copies to device buffers", filter.allocations(),
        filter.allocations() == 1 ? "" : "s", device.transform * ms / ran, device.blur * ms / ran,
        device.pyramid * ms / ran, device.sat * ms / ran, device.zmax * ms / ran, device.classify * ms / ran,
        device.reconstruct * ms / ran, device.upload * ms / ran, device.download * ms / ran, report.decode,
        report.process, report.encode, report.wall, report.written / std::max(report.wall, 1e-9),
        texels / std::max(report.wall, 1e-9) * 1e-6, receivers_done / std::max(report.wall, 1e-9) * 1e-6);
  }
  return static_cast<int>(std::min<size_t>(report.failed, 125));
}

}  // namespace sf::cli
