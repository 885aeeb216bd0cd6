#pragma once
// Layered filtering (methods.md sec. 6): a cascade set's K shadow maps filtered on the device,
// each layer by an ordinary Pipeline of its own (no texel of one layer enters another's filter),
// and one visibility per camera-view receiver from the layer, or the two blended layers, that
// sf::select_cascade picks for it. Method- and layout-blind: single maps, PSSM, TSM and their
// mix are all cascade sets (cascades.hpp), and every method and lookup of FilterOptions works.
//
// Per layer the blur keeps layer 0's world width: layer_filter_options(). Per receiver the
// footprint and the receiver plane are the layer's own (through its Jacobian).
//
// The soft methods (soft.hpp) layer the same way: a SoftFilter per layer under the one area light,
// which keeps its world size and place in every layer (layer_soft_light).
//
// Ownership, queues, events, threads and sub-buffers as pipeline.hpp says for Pipeline: the
// depth maps, view receivers and visibility are the caller's buffers; the LayeredPipeline owns
// its K pipelines and, from the first reconstruct() on, the per-receiver arrays of the layers
// (reallocated when the receiver count changes). reconstruct() waits on the caller's `wait`
// (pass prefilter()'s event) and the next prefilter() must wait on the last reconstruct().
#include <memory>
#include <vector>

#include "shadowfilter/cascades.hpp"
#include "shadowfilter/map_range.hpp"
#include "shadowfilter/pipeline.hpp"
#include "shadowfilter/soft.hpp"

namespace sf {

// The view receivers in new device buffers: DeviceReceivers (device_types.hpp) with count, row
// (the view's width: the receiver plane's neighbours in each layer) and the view part set. With
// `events` the writes are non-blocking and their events are appended to it; without, they block.
// InputError when an array's length differs from view.count().
DeviceReceivers upload_view_receivers(Runtime& runtime, const ViewReceivers& view, EventList* events = nullptr);

// The world size of a layer's texel where the blur is matched: layer_texel_size at the world
// point of its map centre, (u, v, d) = (1/2, 1/2, 1/2). A warped layer's texels vary across its
// map; the centre is the one point every layout has.
double layer_reference_texel(const CascadeSet& set, int layer);

// The options layer k filters with: `options` with the blur scaled so that its world width
// matches layer 0's: s = texel_0 / texel_k (layer_reference_texel), sigma_k = sigma_0 s (sigma_0
// the given sigma, or (2R+1)/6 when it is 0), R_k = round(R_0 s), and 0 (no blur) where R_0 s < 1:
// a blur narrower than one texel of the layer is below what the layer resolves. InputError when
// R_k exceeds kMaxBlurRadius (a layer much finer than layer 0).
// A warped layer's receiver plane also gets a slope-scaled bias of at least kWarpedSlopeBias
// texels (ReceiverPlaneOptions::slope_bias): measured, the least that keeps lit ground lit under
// every warp of tests/core/test_layered.cpp.
constexpr float kWarpedSlopeBias = 0.5f;
FilterOptions layer_filter_options(const FilterOptions& options, const CascadeSet& set, int layer);

// The area light of layer k for the soft methods: sides `size` along the layer's u axis and
// `height` along v (world units; height < 0: a square), lying in the plane at world depth
// `light_plane` along the light's axis. The light's axis and depths are those of the layer's d
// row, d = M2 . p: depth = n . p with n the unit normal of the row, so the layer's d = 0 and 1
// lie at depths near = -M2[3] / |M2.xyz| and far = near + 1 / |M2.xyz| (the layer headers' near
// and far). The result is orthographic, extent 1 / |grad u| (the map's width in world units),
// height scaled by |grad v| / |grad u| (so both sides keep their world lengths on a map whose
// texels are not square), near and far as above, light_distance = near - light_plane.
// InputError for a warped layer (a projective row 3: a light's footprint in it is no rectangle
// of one size) and for one whose u or v row is not perpendicular to its d row.
SoftLight layer_soft_light(const CascadeSet& set, int layer, double size, double height, double light_plane);

class LayeredPipeline {
 public:
  // Validates the set (sf::validate) and the options per layer, and builds one Pipeline of the
  // set's map size per layer with layer_filter_options(). InputError when either is invalid or
  // the buffers do not fit the device.
  LayeredPipeline(std::shared_ptr<Runtime> runtime, const FilterOptions& options, CascadeSet set);
  // The soft methods: one SoftFilter per layer with `options` under layer_soft_light(set, k,
  // options.light.size, options.light.height, light_plane) (the other fields of options.light
  // are not read). InputError as above, and for the set's warped layers.
  LayeredPipeline(std::shared_ptr<Runtime> runtime, const SoftOptions& options, CascadeSet set, double light_plane);

  // Filters layer k's depth map depth[k] (width x height floats, linear [0, 1]) for every k;
  // one event when all are done. InputError when depth does not hold one buffer per layer.
  cl::Event prefilter(const std::vector<cl::Buffer>& depth, const EventList* wait = nullptr);
  // Pipeline::set_depth_range for each layer (one range per layer).
  void set_depth_ranges(const std::vector<MapRange>& ranges);
  // Visibility of every receiver into `visibility` (rx.count floats) from the view part of `rx`
  // (InputError when it is empty; the map part is ignored): the projection kernel, each layer's
  // reconstruction over all receivers (those it does not serve cost a test and a write), then
  // the blend.
  cl::Event reconstruct(const DeviceReceivers& rx, const cl::Buffer& visibility, const EventList* wait = nullptr);

  // What the projection of the last reconstruct() wrote (valid after its event): per receiver
  // `layers` (cl_char2: first, second layer, -1 = none) and `weight` (the second layer's), and
  // per layer k the receivers at k * stride: u, v, d (NaN where k does not serve the receiver)
  // and f (footprint in layer texels); where a layer's lookup follows Jacobians (a footprint
  // lookup with max_anisotropy > 1), `jacobian`: per layer k from 4 k stride, the receivers'
  // Jacobians in layer texels, four planes of count floats (DeviceReceivers::jacobian); else empty.
  struct Projection {
    size_t count = 0, stride = 0;
    cl::Buffer layers, weight, u, v, d, f, visibility;  // visibility: per layer, before the blend
    cl::Buffer jacobian;
  };
  const Projection& projection() const { return proj_; }

  const CascadeSet& cascades() const { return set_; }
  int layer_count() const { return static_cast<int>(pipes_.size() + soft_.size()); }
  bool soft() const { return !soft_.empty(); }
  // Layer k's filter: layer() of a pipeline of FilterOptions, soft_layer() of one of SoftOptions;
  // InputError for the other kind or a k out of range.
  Pipeline& layer(int k);
  const Pipeline& layer(int k) const;
  SoftFilter& soft_layer(int k);
  // The layers' pipelines plus the per-receiver arrays allocated so far.
  size_t device_bytes() const;
  // Bytes reconstruct() allocates per receiver for K layers: u, v, d, f and a visibility per
  // layer, the choice and weight (the Jacobians, where a layer reads them, add 4 floats per layer).
  static size_t bytes_per_receiver(int layers);
  // Device seconds of the last prefilter/reconstruct (waits for their events): every layer's
  // stages summed stage by stage (layer(k).times() has one layer's), the projection and the blend.
  StageTimes times() const;

 private:
  void allocate(size_t count);

  std::shared_ptr<Runtime> rt_;
  CascadeSet set_;
  cl::Buffer params_;  // sf_cascade_params of set_ (shared_types.clh), read by sf_cascade_project
  std::vector<std::unique_ptr<Pipeline>> pipes_;   // empty for the soft methods
  std::vector<std::unique_ptr<SoftFilter>> soft_;  // empty otherwise
  Projection proj_;
  std::vector<DeviceReceivers> layer_rx_;  // sub-buffers of proj_ per layer
  std::vector<cl::Buffer> layer_vis_;
  cl::Event project_done_, blend_done_;
  // The fills that fault in the projection's buffers on a CPU device (StageTimes::resident),
  // reported with the frame that allocated them.
  cl::Event resident_first_, resident_done_;
};

// Host convenience (what the CLI uses), the layered twin of filter(): uploads the maps (one per
// layer, the set's size) and the view, runs, downloads. Where a lookup's limit depends on the
// depth range (sat with esm, evsm), each map's range comes from its host copy.
struct LayeredResult : VisibilityResult {
  // visibility: view.width x view.height; background: non-finite view depth; outside: no layer
  // serves them; times: LayeredPipeline::times() with the transfers.
  std::vector<size_t> per_layer;  // receivers reading layer k (a blended one counts in both)
  size_t blended = 0;             // receivers mixing two layers
};
LayeredResult filter_layered(std::shared_ptr<Runtime> runtime, const FilterOptions& options, const CascadeSet& set,
                             const std::vector<HostImage>& maps, const ViewReceivers& view);
// The same with a soft method per layer (the LayeredPipeline of SoftOptions and light_plane).
LayeredResult filter_layered(std::shared_ptr<Runtime> runtime, const SoftOptions& options, const CascadeSet& set,
                             double light_plane, const std::vector<HostImage>& maps, const ViewReceivers& view);

}  // namespace sf
