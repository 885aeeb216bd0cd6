// What an error is measured against (the references), the Pareto front of (time, error) against
// one of them, and the labels that name it on a plot.
#include <algorithm>
#include <cmath>
#include <numeric>

#include "eval_util.hpp"
#include "evaluate.hpp"
#include "shadowfilter/errors.hpp"

namespace sf::eval {

Reference parse_reference(const std::string& name) {
  for (Reference r : {Reference::Soft, Reference::Hard, Reference::Target, Reference::Self})
    if (name == reference_name(r)) return r;
  throw InputError("--pareto-reference must be soft, hard, target or self, got '" + name + "'");
}

const char* reference_name(Reference r) {
  switch (r) {
    case Reference::Soft:
      return "soft";
    case Reference::Hard:
      return "hard";
    case Reference::Target:
      return "target";
    case Reference::Self:
      break;
  }
  return "self";
}

std::string target_text(const TargetFilter& t) {
  std::string s = "R=" + std::to_string(t.blur.radius);
  if (t.blur.radius > 0 && t.blur.sigma > 0) s += " sigma=" + std::to_string(t.blur.sigma);
  return s + " " + detail::lookup_name(t.lookup);
}

std::string reference_text(Reference r, const TargetFilter& t) {
  switch (r) {
    case Reference::Soft:
      return "ray-traced soft shadow (reference_soft.exr)";
    case Reference::Hard:
      return "ray-traced hard shadow (reference_hard.exr)";
    case Reference::Target:
      return "s_ref of the target filter " + target_text(t);
    case Reference::Self:
      break;
  }
  return "s_ref of each configuration's own filter (fidelity)";
}

bool has_reference(const Scene& s, Reference r) {
  if (r == Reference::Soft) return s.ref_soft.texels() == s.receivers.count() && s.ref_soft.texels() > 0;
  if (r == Reference::Hard) return s.ref_hard.texels() == s.receivers.count() && s.ref_hard.texels() > 0;
  return true;
}

Reference plot_reference(const Scene& s, Reference requested, std::string* note) {
  if (note) note->clear();
  if (has_reference(s, requested)) return requested;
  if (note)
    *note = "scene '" + s.name + "' has no reference_" + reference_name(requested) +
            ".exr: errors against the target filter's s_ref instead";
  return Reference::Target;
}

std::string metric_text(const std::string& metric) {
  check_metric(metric);
  if (metric == "rmse") return "RMSE";
  if (metric == "p99") return "p99 |error|";
  if (metric == "max") return "max |error|";
  if (metric == "frac_1_255") return "fraction |error| > 1/255";
  if (metric == "frac_005") return "fraction |error| > 0.05";
  if (metric == "leak") return "fraction brighter by > 0.05";
  return "fraction darker by > 0.05";
}

bool split_metric(const std::string& name, std::string* metric, Reference* ref) {
  static const std::pair<const char*, Reference> prefixes[] = {{"soft_", Reference::Soft},
                                                               {"hard_", Reference::Hard},
                                                               {"target_", Reference::Target},
                                                               {"self_", Reference::Self},
                                                               {"sref_", Reference::Self}};
  for (const auto& [p, r] : prefixes) {
    const std::string prefix = p;
    if (name.rfind(prefix, 0) == 0) {
      *metric = name.substr(prefix.size());
      *ref = r;
      return true;
    }
  }
  *metric = name;
  return false;
}

const ErrorStats& row_errors(const Row& r, Reference ref) {
  switch (ref) {
    case Reference::Soft:
      return r.soft;
    case Reference::Hard:
      return r.hard;
    case Reference::Target:
      return r.target;
    case Reference::Self:
      break;
  }
  return r.sref;
}

// A reference the row was not measured against has no error: NaN keeps it off every front.
double row_error(const Row& r, Reference ref, const std::string& metric) {
  const ErrorStats& e = row_errors(r, ref);
  return e.valid ? metric_value(e, metric) : NAN;
}

double row_metric(const Row& r, const std::string& name) {
  std::string metric;
  Reference ref = Reference::Self;
  split_metric(name, &metric, &ref);
  return row_error(r, ref, metric);
}

// Sorted by time, then error: a point is on the front when its error is below every faster
// point's (and below every equally fast one's that comes first), or when it equals the last
// front point in both time and error (a tie dominates neither).
std::vector<size_t> pareto_front(const std::vector<double>& time, const std::vector<double>& error) {
  if (time.size() != error.size()) throw InputError("pareto_front: times and errors differ in count");
  std::vector<size_t> idx;
  for (size_t i = 0; i < time.size(); ++i)
    if (std::isfinite(time[i]) && std::isfinite(error[i])) idx.push_back(i);
  std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) {
    if (time[a] != time[b]) return time[a] < time[b];
    return error[a] < error[b];
  });
  std::vector<size_t> front;
  for (size_t i : idx) {
    if (front.empty() || error[i] < error[front.back()] ||
        (error[i] == error[front.back()] && time[i] == time[front.back()]))
      front.push_back(i);
  }
  return front;
}

std::vector<size_t> pareto_front(const std::vector<Row>& rows, Reference ref, const std::string& metric) {
  std::vector<double> t(rows.size()), e(rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    t[i] = rows[i].time_ms;
    e[i] = row_error(rows[i], ref, metric);
  }
  return pareto_front(t, e);
}

std::vector<size_t> pareto_front(const std::vector<Row>& rows, const std::string& name) {
  std::string metric;
  Reference ref = Reference::Self;
  split_metric(name, &metric, &ref);
  return pareto_front(rows, ref, metric);
}

std::string PlotLabels::description() const { return title + "\n" + subtitle + "\n" + x_axis + "\n" + y_axis; }

PlotLabels pareto_labels(const Scene& scene, size_t configurations, Reference ref, const std::string& metric,
                         const TargetFilter& target, const std::string& note) {
  PlotLabels l;
  const std::string against = metric_text(metric) + " against " + reference_text(ref, target);
  l.title = scene.name + ": time vs " + against;
  const bool traced = ref == Reference::Soft || ref == Reference::Hard;
  const size_t counted = traced ? scene.traced_count : scene.valid_count;
  l.subtitle = std::to_string(configurations) + " configurations; " + std::to_string(counted) + " receivers" +
               (traced && scene.receivers.has_ndl ? " facing the light" : "") + "; box = Pareto front";
  if (ref == Reference::Self) l.subtitle += "; sm and pcf are 0 by definition";
  if (!note.empty()) l.subtitle += "; " + note;
  l.x_axis = "median time per frame, ms (log scale)";
  l.y_axis = against;
  return l;
}

}  // namespace sf::eval
