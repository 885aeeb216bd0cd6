#pragma once
// ESM failure classification as an optional stage after the reconstruction (Annen 2008 ch. 7.3,
// kernels/esm_classify.cl): what it allocates, the z-max pyramid it builds from the raw depth,
// the kernel that flags receivers and replaces their visibility, and its flags. A Pipeline runs
// one when FilterOptions::esm_classify asks for it; a caller with its own reconstruction may run
// one itself on the pipeline's tables. Only methods the registry marks classifiable take it.
#include <memory>

#include "shadowfilter/device_types.hpp"
#include "shadowfilter/pyramids.hpp"

namespace sf {

class ClassifyStage {
 public:
  // Adds the stage's buffers to `plan` (the z-max chain in zmax mode; one flag byte per
  // receiver). Throws InputError when the options classify with a method that cannot.
  static void add_to_plan(const FilterOptions& options, int width, int height, BufferPlan& plan);

  ClassifyStage(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height);
  // Allocates what `plan` holds for the stage (a plan add_to_plan filled, e.g. the Pipeline's).
  ClassifyStage(std::shared_ptr<Runtime> runtime, FilterOptions options, int width, int height, const BufferPlan& plan);

  // Before reconstruction: the z-max pyramid of the raw depth (zmax mode), after `wait`. Returns
  // the pyramid's last event (an empty event when the mode needs none). Keeps `depth` for classify().
  cl::Event prepare(const cl::Buffer& depth, const EventList* wait);
  // After the reconstruction's event in `wait`: flags the receivers and rewrites their
  // visibility; `basis` and `lookup` are the tables the reconstruction read.
  cl::Event classify(const cl::Buffer& basis, const LookupBuffers& lookup, const DeviceReceivers& receivers,
                     const cl::Buffer& visibility, const EventList* wait);

  // One uchar per receiver of the last classify() (1 = flagged).
  const cl::Buffer& flags() const { return flags_; }
  // Seconds of the last z-max pyramid and classification (profiling queues).
  void add_times(StageTimes& t) const;

 private:
  std::shared_ptr<Runtime> rt_;
  FilterOptions options_;
  int width_, height_;
  cl::Buffer zmax_chain_, depth_, flags_;
  size_t flags_count_ = 0;
  cl::Event zmax_first_, zmax_done_;
  cl::Event classify_done_;
};

}  // namespace sf
