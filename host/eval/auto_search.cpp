// --auto: candidates in estimated-cost order, measured until the bound is met, the finalists
// re-measured in interleaved rounds (evaluate.hpp says why).
#include <algorithm>
#include <cmath>

#include "eval_util.hpp"
#include "evaluate.hpp"
#include "method_catalogue.hpp"
#include "shadowfilter/errors.hpp"
#include "shadowfilter/methods.hpp"

namespace sf::eval {

using detail::fmt;
using detail::median;

double estimated_cost(const FilterOptions& o, int map_w, int map_h, size_t receivers) {
  // Nanoseconds per map texel for the prefilter stages and per receiver for the reconstruction:
  // the method's coefficients (evaluate's catalogue), the stages' below (docs/results.md "cost model").
  const MethodDesc& m = *o.method;
  const CostModel& k = catalogue_entry(o.method).cost;
  const double T = double(map_w) * map_h, N = double(receivers);
  if (m.raw_depth) {
    const double side = 2.0 * o.blur.radius + 2.0;  // the support's texels, each tested
    return 1e-6 * N * (k.reconstruct + k.per_support_texel * side * side);
  }
  const int ch = m.channels(o);
  const double bytes = double(basis_bytes_per_texel(m, o));
  double texel = k.transform_per_channel * ch;
  if (o.blur.radius > 0) texel += 0.25 * bytes * (1.0 + o.blur.radius / 8.0);
  if (o.lookup.kind == Lookup::Mips) texel += 0.1 * bytes;
  if (o.lookup.kind == Lookup::Sat) texel += 0.5 * bytes + 0.5 * ch;
  double rx = k.reconstruct + k.reconstruct_per_channel * ch;
  if (o.lookup.kind == Lookup::Mips) rx *= 2.0;  // two bilinear levels
  if (o.lookup.kind == Lookup::Sat) rx *= 2.5;   // four float-float corners
  if (classify_mode(o) == EsmClassify::Threshold) rx += 6.0;
  if (classify_mode(o) == EsmClassify::ZMax) {
    texel += 0.4;  // the z-max pyramid of the depth
    rx += 10.0;
  }
  return 1e-6 * (T * texel + N * rx);
}

namespace {

// What the kernels compute for these options: two candidates with the same key are one
// configuration (evsm's warps above the f16 limit pack to the same clamped value).
std::string candidate_key(const MethodDesc& m, const FilterOptions& o) {
  std::string key = o.method.name() + "/" + storage_name(o.storage) + "/" + std::to_string(int(o.lookup.kind)) + "/" +
                    std::to_string(int(classify_mode(o))) + "/";
  for (uint8_t b : m.pack_params(o)) key += std::to_string(b) + ",";
  return key + m.defines(o);
}

}  // namespace

std::vector<AutoCandidate> auto_candidates(const Scene& scene, const AutoRequest& req, const FilterOptions& target,
                                           std::vector<Skipped>* refused) {
  const std::vector<std::string> names = req.methods.empty() ? parse_methods("all") : req.methods;
  std::vector<Lookup> lookups{Lookup::Bilinear};
  if (target.lookup.kind != Lookup::Bilinear) lookups.push_back(target.lookup.kind);
  std::vector<FilterOptions> all;
  for (const auto& name : names) {
    FilterOptions base = target;
    base.method = method(name);
    const MethodDesc& m = *base.method;
    base.esm_classify = EsmClassifyOptions{};
    base.lookup.kind = Lookup::Bilinear;
    if (m.raw_depth) {
      base.depth_test.bias = float(req.sref_bias);
      all.push_back(base);  // sm / pcf: no basis, no lookup (they follow no footprint)
      continue;
    }
    std::vector<std::string> seen;
    for (const auto& p : auto_variants(base))
      for (const StorageLimit& st : m.storages)
        for (Lookup lk : lookups) {
          FilterOptions o = p;
          o.storage = st.storage;
          o.lookup.kind = lk;
          o = m.fitted(o);  // within the storage's limits (esm in f16: c = 20)
          try {
            m.validate(o);
          } catch (const InputError& e) {
            if (refused) refused->push_back({scene.name, config_label(o), e.what()});
            continue;
          }
          const std::string key = candidate_key(m, o);
          if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
          seen.push_back(key);
          all.push_back(o);
        }
  }
  std::vector<AutoCandidate> out;
  for (const auto& o : all)
    out.push_back({o, estimated_cost(o, scene.depth.width, scene.depth.height, scene.valid_count)});
  std::stable_sort(out.begin(), out.end(),
                   [](const AutoCandidate& a, const AutoCandidate& b) { return a.cost < b.cost; });
  return out;
}

TimedChoice choose_by_times(const std::vector<std::vector<double>>& rounds, const std::vector<double>& cost,
                            double time_tolerance) {
  if (rounds.empty() || cost.empty()) throw InputError("choose_by_times: no rounds or no finalists");
  const size_t n = cost.size();
  std::vector<std::vector<double>> ratio(n);  // ratio[k]: finalist k's time over the round's fastest
  for (const auto& t : rounds) {
    if (t.size() != n)
      throw InputError("choose_by_times: a round has " + std::to_string(t.size()) + " times for " + std::to_string(n) +
                       " finalists");
    const double best = *std::min_element(t.begin(), t.end());
    for (size_t k = 0; k < n; ++k) ratio[k].push_back(t[k] / best);
  }
  TimedChoice c;
  std::vector<double> noise;
  for (size_t k = 0; k < n; ++k) {
    c.score.push_back(median(ratio[k]));
    noise.push_back(c.score[k] / *std::min_element(ratio[k].begin(), ratio[k].end()) - 1.0);
  }
  c.noise = n > 1 ? median(noise) : 0.0;
  c.tolerance = std::max(time_tolerance, c.noise);
  c.order.resize(n);
  for (size_t k = 0; k < n; ++k) c.order[k] = k;
  std::stable_sort(c.order.begin(), c.order.end(), [&](size_t a, size_t b) { return c.score[a] < c.score[b]; });
  const double best = c.score[c.order.front()];
  c.pick = c.order.front();
  for (size_t k : c.order)
    if (c.score[k] <= best * (1.0 + c.tolerance) && cost[k] < cost[c.pick]) c.pick = k;
  return c;
}

// The choice among the candidates under the bound (`hits`, indices in res.tried). One run's time
// on a loaded machine is off by tens of percent, and a short quiet moment can make one
// candidate's fastest run half the others', so the finalists run again in interleaved rounds and
// are compared within each round (choose_by_times: the median over the rounds of a finalist's
// time over the round's fastest, ties within the measured noise to the lowest estimate), which
// makes the choice repeatable. Finalists: the hits whose first pass is within 3x of the fastest,
// at most 8.
// A soft row runs its soft options again, any other its filter options.
static double rerun_ms(const std::shared_ptr<Runtime>& rt, const Row& row, const Scene& scene,
                       const TimingSettings& t) {
  return row.soft_options ? measure(rt, *row.soft_options, scene, t).min_ms : measure(rt, row.options, scene, t).min_ms;
}

static void choose_measured(const std::shared_ptr<Runtime>& rt, const Scene& scene, const TimingSettings& timing,
                            int final_rounds, double time_tolerance, const std::vector<size_t>& hits, AutoResult& res) {
  constexpr size_t kMaxFinalists = 8;
  std::vector<size_t> fin = hits;
  std::stable_sort(fin.begin(), fin.end(),
                   [&](size_t a, size_t b) { return res.tried[a].min_ms < res.tried[b].min_ms; });
  const double first_best = res.tried[fin.front()].min_ms;
  while (fin.size() > kMaxFinalists || res.tried[fin.back()].min_ms > 3.0 * first_best) fin.pop_back();
  std::vector<std::vector<double>> rounds;  // the fastest run of each finalist per round
  const TimingSettings t{1, std::max(1, timing.runs)};
  for (int round = 0; round < final_rounds && fin.size() > 1; ++round) {
    std::vector<double> pass(fin.size());
    for (size_t j = 0; j < fin.size(); ++j) {
      const size_t k = (j + size_t(round)) % fin.size();  // rotate: no fixed position in a round
      Row& row = res.tried[fin[k]];
      pass[k] = rerun_ms(rt, row, scene, t);
      row.min_ms = std::min(row.min_ms, pass[k]);
      row.runs += t.runs;
    }
    rounds.push_back(pass);
  }
  if (rounds.empty()) {  // no rounds: the first pass decides
    rounds.emplace_back();
    for (size_t i : fin) rounds.back().push_back(res.tried[i].min_ms);
  }
  std::vector<double> cost;
  for (size_t i : fin) cost.push_back(res.tried_cost[i]);
  const TimedChoice c = choose_by_times(rounds, cost, time_tolerance);
  res.noise = c.noise;
  res.tolerance = c.tolerance;
  for (size_t k : c.order) {
    const Row& row = res.tried[fin[k]];
    res.finalists.push_back({row.label, row.min_ms, c.score[k], cost[k]});
  }
  const size_t pick = c.pick, fastest = c.order.front();
  if (pick != fastest)
    res.tie = res.tried[fin[fastest]].label + " scored " + fmt(100.0 * (c.score[pick] / c.score[fastest] - 1.0), 2) +
              "% faster, within the " + fmt(100.0 * res.tolerance, 2) + "% band, and " +
              (res.tried[fin[pick]].soft_options ? "uses more device memory" : "has a higher estimate");
  res.chosen = res.tried[fin[pick]].options;
  res.chosen_row = res.tried[fin[pick]];
  res.chosen_score = c.score[pick];
}

AutoResult choose_auto(const std::shared_ptr<Runtime>& rt, const Scene& scene, const AutoRequest& req,
                       const std::function<void(size_t, size_t)>& progress) {
  check_metric(req.metric);
  if (!(req.max_error >= 0)) throw InputError("--max-error must be a non-negative number");
  if (!(req.cost_slack >= 1)) throw InputError("--auto cost slack must be >= 1");
  if (req.final_rounds < 0 || !(req.time_tolerance >= 0))
    throw InputError("--auto final rounds and tolerance must be >= 0");
  AutoResult res;
  FilterOptions target = req.target;
  if (req.lookup_from_scene) target.lookup.kind = scene.max_footprint > 1.0 ? Lookup::Mips : Lookup::Bilinear;
  // Mips / SAT with every footprint <= 1 read level 0 with the bilinear (mips: LOD 0) or unit-box
  // (= bilinear) weights: the table would only cost time.
  if (scene.max_footprint <= 1.0) {
    const bool asked = target.lookup.kind != Lookup::Bilinear;
    res.skipped.push_back(
        std::string(asked && target.lookup.kind == Lookup::Sat ? "summed-area table" : "mip pyramid") +
        ": every footprint is <= 1 texel (max " + fmt(scene.max_footprint) + "), so the lookup equals bilinear");
    target.lookup.kind = Lookup::Bilinear;
  }
  res.target = target;
  res.notes.push_back(
      "target: s_ref with " +
      std::string(target.blur.radius > 0 ? "Gaussian R=" + std::to_string(target.blur.radius) : "no prefilter") +
      (target.lookup.kind == Lookup::Mips  ? ", trilinear mips"
       : target.lookup.kind == Lookup::Sat ? ", box (sat)"
                                           : ", bilinear") +
      ", depth bias " + fmt(req.sref_bias) + "; " + req.metric + " <= " + fmt(req.max_error) + " over " +
      std::to_string(scene.valid_count) + " receivers (max footprint " + fmt(scene.max_footprint) + " texels)");
  SrefCache cache(scene, req.sref_bias);
  const std::vector<double>& sref = cache.get(target.blur, target.lookup.kind);

  const std::vector<AutoCandidate> cands = auto_candidates(scene, req, target, &res.refused);
  std::vector<size_t> hits;  // indices in res.tried of the candidates under the bound
  double limit = INFINITY;   // measure up to cost_slack x the first hit's estimate
  size_t done = 0;
  for (const auto& c : cands) {
    if (c.cost > limit) {
      res.not_tried.push_back(c);
      continue;
    }
    Row row;
    try {
      Measured m = measure(rt, c.options, scene, req.timing);
      row = timed_row(scene, c.options, m);
      row.sref = error_stats(m.visibility, sref, scene.valid);
    } catch (const InputError& e) {
      res.refused.push_back({scene.name, config_label(c.options), e.what()});
      if (progress) progress(++done, cands.size());
      continue;
    }
    if (progress) progress(++done, cands.size());
    res.tried.push_back(row);
    res.tried_cost.push_back(c.cost);
    if (metric_value(row.sref, req.metric) > req.max_error) continue;
    if (res.first_hit.empty()) {
      res.first_hit = row.label;
      limit = c.cost * req.cost_slack;
    }
    hits.push_back(res.tried.size() - 1);
  }
  if (progress) progress(cands.size(), cands.size());
  if (!hits.empty()) {
    choose_measured(rt, scene, req.timing, req.final_rounds, req.time_tolerance, hits, res);
    res.found = true;
  }
  // What the choice does without, and why.
  bool any_zmax = false;
  for (const auto& c : cands) any_zmax |= classify_mode(c.options) == EsmClassify::ZMax;
  if (!res.found || classify_mode(res.chosen) != EsmClassify::ZMax)
    res.skipped.push_back(std::string("z-max pyramid: ") +
                          (any_zmax ? "the chosen configuration does not classify ESM failures"
                                    : "no candidate classifies ESM failures (esm not among the methods)"));
  if (res.found && res.chosen.lookup.kind == Lookup::Bilinear && target.lookup.kind != Lookup::Bilinear)
    res.skipped.push_back(std::string(target.lookup.kind == Lookup::Mips ? "mip pyramid" : "summed-area table") +
                          ": bilinear already meets the bound at the scene's footprints");
  // A method whose channel count follows its order (csm): say when smaller orders miss.
  if (res.found && res.chosen.method->order_sets_channels) {
    const MethodDesc& m = *res.chosen.method;
    for (const auto& row : res.tried)
      if (row.method == res.chosen.method && m.channels(row.options) < m.channels(res.chosen) &&
          metric_value(row.sref, req.metric) > req.max_error) {
        res.notes.push_back(m.name + ": smaller orders miss the bound (" + row.label + ": " + req.metric + " " +
                            fmt(metric_value(row.sref, req.metric)) + ")");
        break;
      }
  }
  if (!res.not_tried.empty()) {
    std::map<std::string, int> by_method;
    for (const auto& c : res.not_tried) ++by_method[c.options.method.name()];
    std::string list;
    for (const auto& [m, n] : by_method) list += (list.empty() ? "" : ", ") + m + " (" + std::to_string(n) + ")";
    res.skipped.push_back(std::to_string(res.not_tried.size()) + " configurations estimated at more than " +
                          fmt(req.cost_slack) + "x the first one under the bound (" + res.first_hit + "): " + list);
  }
  return res;
}

const ErrorStats& auto_errors(const Row& row) { return row.soft_options ? row.soft : row.sref; }

AutoResult choose_soft_auto(const std::shared_ptr<Runtime>& rt, const Scene& scene, const SoftAutoRequest& req,
                            const std::function<void(size_t, size_t)>& progress) {
  check_metric(req.metric);
  if (!(req.max_error >= 0)) throw InputError("--max-error must be a non-negative number");
  if (req.final_rounds < 0 || !(req.time_tolerance >= 0))
    throw InputError("--auto final rounds and tolerance must be >= 0");
  if (!scene.light)
    throw InputError((scene.no_light.empty() ? std::string("the scene has no area light") : scene.no_light) +
                     ": the soft methods need one");
  const HostImage& ref = scene.ref_soft;
  if (ref.width != scene.receivers.width || ref.height != scene.receivers.height || ref.channels != 1)
    throw InputError(req.reference + " is " + std::to_string(ref.width) + "x" + std::to_string(ref.height) + " with " +
                     std::to_string(ref.channels) + " channel(s); the receivers need one channel of " +
                     std::to_string(scene.receivers.width) + "x" + std::to_string(scene.receivers.height));
  // The counted receivers' reference is a visibility: a value outside [0, 1] is not one (a
  // radiance image, a wrong channel), and is refused rather than compared with.
  for (size_t i = 0; i < ref.texels(); ++i)
    if (scene.traced[i] && !(ref.data[i] >= 0.0f && ref.data[i] <= 1.0f))
      throw InputError(req.reference + ": pixel (" + std::to_string(i % ref.width) + ", " +
                       std::to_string(i / ref.width) + ") holds " + fmt(ref.data[i]) +
                       ", not a visibility in [0, 1], where the receivers face the light");
  if (scene.traced_count == 0)
    throw InputError("no receiver inside the map faces the light: nothing to measure the choice on");
  AutoResult res;
  res.notes.push_back("target: " + req.reference + "; " + req.metric + " <= " + fmt(req.max_error) + " over " +
                      std::to_string(scene.traced_count) + " receivers inside the map and facing the light");
  const std::vector<SoftMethod> methods =
      req.methods.empty()
          ? std::vector<SoftMethod>{SoftMethod::Pcss, SoftMethod::Cssm, SoftMethod::Ssmm, SoftMethod::SsmmImproved}
          : req.methods;
  const std::vector<SoftOptions> grid = make_soft_grid(methods, req.grid, req.base);
  std::vector<size_t> hits;
  size_t done = 0;
  for (const SoftOptions& o : grid) {
    Row row;
    try {
      row = evaluate_soft_config(rt, scene, o, req.timing);
    } catch (const InputError& e) {
      res.refused.push_back({scene.name, soft_label(o), e.what()});
      if (progress) progress(++done, grid.size());
      continue;
    }
    if (progress) progress(++done, grid.size());
    row.visibility.clear();
    res.tried.push_back(row);
    res.tried_cost.push_back(row.device_bytes / 1048576.0);  // ties go to the smaller footprint
    if (metric_value(row.soft, req.metric) <= req.max_error) hits.push_back(res.tried.size() - 1);
  }
  if (!hits.empty()) {
    choose_measured(rt, scene, req.timing, req.final_rounds, req.time_tolerance, hits, res);
    res.found = true;
  }
  return res;
}

std::string describe(const AutoResult& r, const std::string& metric) {
  std::ostringstream s;
  for (const auto& n : r.notes) s << "auto: " << n << "\n";
  if (!r.found) {
    s << "auto: no configuration meets the bound";
    const Row* best = nullptr;
    for (const auto& row : r.tried)
      if (!best || metric_value(auto_errors(row), metric) < metric_value(auto_errors(*best), metric)) best = &row;
    if (best)
      s << "; closest: " << best->label << " (" << metric << " " << fmt(metric_value(auto_errors(*best), metric))
        << ", " << fmt(best->time_ms) << " ms)";
    s << "\n";
  } else {
    const Row& c = r.chosen_row;
    const ErrorStats& e = auto_errors(c);
    s << "auto: chose " << c.label << ": " << fmt(c.min_ms) << " ms (fastest of " << c.runs
      << " runs; median of the first pass " << fmt(c.time_ms) << "), " << metric << " " << fmt(metric_value(e, metric))
      << " (p99 " << fmt(e.p99) << ", rmse " << fmt(e.rmse) << ", max " << fmt(e.max) << "), "
      << fmt(c.device_bytes / 1048576.0, 3) << " MiB\n";
    if (c.soft_options)
      s << "auto: why: of the " << r.tried.size() << " configurations measured, the " << r.finalists.size()
        << " under the bound ran again in interleaved rounds and this one was the fastest"
        << (r.tie.empty() ? "" : " within noise (" + r.tie + ")") << "\n";
    else
      s << "auto: why: " << r.first_hit << " was the first configuration under the bound in estimated-cost order; "
        << "of the " << r.tried.size() << " tried up to the cost slack, the " << r.finalists.size()
        << " under the bound ran again in interleaved rounds and this one was the fastest"
        << (r.tie.empty() ? "" : " within noise (" + r.tie + ")") << "\n";
    std::string list;
    for (const auto& f : r.finalists)
      list += (list.empty() ? "" : ", ") + f.label + " x" + fmt(f.score, 3) + " (" + fmt(f.min_ms) + " ms)";
    s << "auto: finalists (median time over the round's fastest; fastest run): " << list << "; measured noise "
      << fmt(100.0 * r.noise, 2) << "%, tie band " << fmt(100.0 * r.tolerance, 2) << "%\n";
  }
  for (const auto& k : r.skipped) s << "auto: skipped " << k << "\n";
  for (size_t i = 0; i < r.tried.size(); ++i) {
    const Row& row = r.tried[i];
    s << "auto:   tried " << row.label << ": " << fmt(row.time_ms) << " ms ("
      << (row.soft_options ? fmt(r.tried_cost[i], 3) + " MiB" : "estimate " + fmt(r.tried_cost[i], 3)) << "), "
      << metric << " " << fmt(metric_value(auto_errors(row), metric)) << "\n";
  }
  // Refusals grouped by reason.
  std::map<std::string, std::string> by_reason;
  for (const auto& k : r.refused) {
    auto& list = by_reason[k.reason];
    list += (list.empty() ? "" : ", ") + k.label;
  }
  for (const auto& [reason, list] : by_reason) s << "auto: refused (" << reason << "): " << list << "\n";
  return s.str();
}

}  // namespace sf::eval
