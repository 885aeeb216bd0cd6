// `filter --frames LIST` and `filter --shadow-map A B ... --output-dir DIR`: a batch of frames
// on one warm device (FrameFilter), decoding the next frame and encoding the last one on worker
// threads while the device runs the current one (batch_runner.hpp).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <mutex>

#include "batch_runner.hpp"
#include "commands.hpp"
#include "filter_options.hpp"
#include "frame_list.hpp"
#include "image_io.hpp"
#include "verbose.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/frame_filter.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::cli {
namespace {

struct LoadedFrame {
  HostImage depth;
  std::shared_ptr<const Receivers> receivers;
};

struct FilteredFrame {
  HostImage visibility;
};

// The receivers of the frame before, reused while frames name the same file (and, for planar
// receivers, the same map size): a sequence over one camera decodes them once. Frames decode on
// several threads (batch_runner.hpp): the lock makes the second of two frames that need one
// file wait for the first one's copy.
class ReceiverCache {
 public:
  std::shared_ptr<const Receivers> get(const FrameSpec& f, const HostImage& depth, const io::DepthLoadOptions& load) {
    const std::string key = f.receivers.empty() ? "depth=" + f.receiver_depth + " " + std::to_string(depth.width) +
                                                      "x" + std::to_string(depth.height)
                                                : f.receivers;
    std::lock_guard<std::mutex> lock(mutex_);
    if (key != key_ || !receivers_) {
      receivers_.reset();
      receivers_ = std::make_shared<const Receivers>(io::load_receivers(f.receivers, f.receiver_depth, depth, load));
      key_ = key;
    }
    return receivers_;
  }

 private:
  std::mutex mutex_;
  std::string key_;
  std::shared_ptr<const Receivers> receivers_;
};

void add_times(StageTimes& total, const StageTimes& t) {
  total.transform += t.transform;
  total.blur += t.blur;
  total.reconstruct += t.reconstruct;
  total.upload += t.upload;
  total.download += t.download;
  total.pyramid += t.pyramid;
  total.sat += t.sat;
  total.zmax += t.zmax;
  total.classify += t.classify;
}

}  // namespace

int run_filter_batch(const FilterArgs& a) {
  if (a.auto_args.enabled)
    throw InputError("--auto measures one input; run it on one frame and give the batch the options it chose");
  if (!a.flags_out.empty()) throw InputError("--flags-out writes one frame's mask; it does not take a batch");
  std::vector<FrameSpec> frames;
  if (!a.frames.empty()) {
    frames = read_frame_list(a.frames);
  } else {
    if (a.shadow_maps.empty()) throw InputError("--output-dir needs --shadow-map A [B ...]");
    if (a.receivers.empty() == a.receiver_depth.empty())
      throw InputError("give exactly one of --receivers or --receiver-depth");
    frames = frames_of_maps(a.shadow_maps, a.receivers, a.receiver_depth, a.output_dir, ".exr");
    std::error_code ec;
    std::filesystem::create_directories(a.output_dir, ec);
    if (ec) throw InputError("--output-dir '" + a.output_dir + "': cannot create it (" + ec.message() + ")");
  }
  std::vector<std::vector<std::string>> previews(frames.size());
  if (a.preview)
    for (size_t i = 0; i < frames.size(); ++i) try {
        previews[i] = {io::preview_path(frames[i].output)};
      } catch (const InputError& e) {
        throw InputError(frames[i].where + ": " + e.what());
      }
  check_batch_outputs(frames, previews, a.frames);

  const io::DepthLoadOptions load = depth_load_options(a);
  auto runtime = Runtime::create(a.device);
  apply_verbose(*runtime, a.verbose);
  FrameFilter filter(runtime, a.options);
  ReceiverCache receivers;
  StageTimes device;
  size_t texels = 0, receivers_done = 0;

  BatchSettings settings;
  settings.keep_going = a.keep_going;
  settings.progress = !a.quiet && ::isatty(STDERR_FILENO);
  const BatchReport report = run_batch<LoadedFrame, FilteredFrame>(
      frames, settings,
      [&](const FrameSpec& f) {
        LoadedFrame loaded;
        loaded.depth = io::load_depth_map(f.shadow_map, load);
        loaded.receivers = receivers.get(f, loaded.depth, load);
        return loaded;
      },
      [&](const FrameSpec&, LoadedFrame& loaded) {
        FilterResult r = filter.run(loaded.depth, *loaded.receivers);
        add_times(device, r.times);
        texels += loaded.depth.texels();
        receivers_done += loaded.receivers->count();
        return FilteredFrame{std::move(r.visibility)};
      },
      [&](const FrameSpec& f, const FilteredFrame& done) {
        std::vector<io::ImageToWrite> outputs{{f.output, &done.visibility}};
        if (a.preview) outputs.push_back({io::preview_path(f.output), &done.visibility});
        io::write_images(outputs);
      });

  if (!a.quiet) {
    const double ms = 1e3;
    const size_t ran = std::max<size_t>(report.frames - report.failed, 1);
    std::printf(
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
