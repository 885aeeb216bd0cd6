// Summed-area tables (kernels/sat.cl): two launches, double (or float-float) accumulation stored
// as float-float, the row prefix in transposed 8x8 blocks.
#include <algorithm>
#include <string>

#include "shadowfilter/errors.hpp"
#include "shadowfilter/pyramids.hpp"

namespace sf {
namespace {
constexpr int kStrip = 256;  // columns per work-item of sf_sat_bands (SF_SAT_STRIP)
}  // namespace

SatLayout sat_layout(const ImageShape& shape) {
  SatLayout L;
  // Bands of rows: one work-item each in the second launch (enqueue_sat takes one band per
  // channel when the channels alone fill the device). 16 bands keep two CPU cores busy
  // while the carries a band reads (the column sums of the bands above it, one double per
  // column each) stay a few percent of the image.
  L.bands = std::clamp(shape.height / 32, 1, 16);
  L.band_rows = (shape.height + L.bands - 1) / L.bands;
  L.bands = (shape.height + L.band_rows - 1) / L.band_rows;
  L.table_floats = 2 * size_t(shape.channels) * (size_t(shape.width) + 1) * (size_t(shape.height) + 1);
  L.band_floats = 4 * size_t(shape.channels) * L.bands * size_t(shape.width);  // 2 rows of doubles
  return L;
}

PassEvents enqueue_sat(Runtime& rt, Storage storage, const cl::Buffer& src, const cl::Buffer& table,
                       const cl::Buffer& band_scratch, const ImageShape& shape, const EventList* wait,
                       SatAccumulator accumulator) {
  SatLayout L = sat_layout(shape);
  // With at least one channel per compute unit the channels alone keep the device busy: one band
  // per channel reads the image once (no band sums), where bands read it twice. 2048^2 x 4
  // channels on 2 cores: 9.0 ms against 12.2-13.2 with 16 bands; 1 channel stays banded (3.8 ms
  // in one band against 2.6).
  if (shape.channels >= int(std::max<cl_uint>(1, rt.info().compute_units))) {
    L.bands = 1;
    L.band_rows = shape.height;
  }
  const bool fp64 = accumulator == SatAccumulator::Auto ? rt.info().fp64 : accumulator == SatAccumulator::Double;
  if (fp64 && !rt.info().fp64)
    throw InputError("SAT: the double accumulator needs cl_khr_fp64, which '" +
                     rt.info().device_name + "' does not support");
  cl::Program p = rt.program({"common.clh", "storage.clh", "vecio.clh", "sat_accum.clh", "sat.cl"},
                             "-cl-std=CL1.2 -DSF_SAT_STRIP=" + std::to_string(kStrip) +
                                 " -DSF_STORAGE=" + std::to_string(static_cast<int>(storage)) +
                                 " -DSF_SAT_FP64=" + (fp64 ? "1" : "0"));
  PassEvents ev;
  cl::Kernel bands(p, "sf_sat_bands");
  bands.setArg(0, src);
  bands.setArg(1, shape.width);
  bands.setArg(2, shape.height);
  bands.setArg(3, L.band_rows);
  bands.setArg(4, L.bands);
  bands.setArg(5, band_scratch);
  // One band has no carries: its band sums would be read by nobody.
  if (L.bands > 1)
    rt.queue().enqueueNDRangeKernel(bands, cl::NullRange,
                                    cl::NDRange((shape.width + kStrip - 1) / kStrip, L.bands, shape.channels),
                                    cl::NDRange(1, 1, 1), wait, &ev.first);
  cl::Kernel rows(p, "sf_sat_rows");
  rows.setArg(0, src);
  rows.setArg(1, shape.width);
  rows.setArg(2, shape.height);
  rows.setArg(3, L.band_rows);
  rows.setArg(4, L.bands);
  rows.setArg(5, band_scratch);
  rows.setArg(6, table);
  EventList after{ev.first};
  rt.queue().enqueueNDRangeKernel(rows, cl::NullRange, cl::NDRange(L.bands, shape.channels),
                                  cl::NDRange(1, 1), L.bands > 1 ? &after : wait, &ev.last);
  if (L.bands == 1) ev.first = ev.last;
  return ev;
}

}  // namespace sf
