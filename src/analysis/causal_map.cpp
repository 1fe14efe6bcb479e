#include "gssm/analysis/causal_map.h"

#include <algorithm>
#include <exception>
#include <string>

#include "gssm/core/error.h"
#include "gssm/core/parallel.h"

namespace gssm {

namespace {
// The elements of `all` (in time order) at or before t.
template <class T>
std::vector<T> upTo(const std::vector<T>& all, double t) {
  const auto end = std::upper_bound(all.begin(), all.end(), t, [](double x, const T& e) { return x < e.t; });
  return std::vector<T>(all.begin(), end);
}
}  // namespace

CausalMapErrors causalMapErrors(const Model& model, EstimatorOptions options,
                                const std::vector<Measurement>& measurements, const std::vector<Input>& inputs,
                                const std::vector<Measurement>& at, RowTimes rows, int threads) {
  options.method = Method::Batch;
  options.batch.threads = 1;  // the solves run side by side instead
  std::vector<std::vector<PointError>> found(at.size());
  const auto errors = runJobs(at.size(), static_cast<std::size_t>(std::max(threads, 1)), [&](std::size_t k) {
    const double t = at[k].t;
    const OfflineRun run = runOffline(model, options, upTo(measurements, t), upTo(inputs, t), {}, {}, rows);
    found[k] = predictionErrorSeries(model, run, inputs, {at[k]});
  });
  CausalMapErrors out;
  for (std::size_t k = 0; k < at.size(); ++k) {
    if (errors[k]) {
      try {
        std::rethrow_exception(errors[k]);
      } catch (const Error& e) {  // the solver's or the data's: named, the others go on
        out.failed.emplace_back(at[k].t, e.what());
      }
      continue;
    }
    out.errors.insert(out.errors.end(), found[k].begin(), found[k].end());
  }
  return out;
}

}  // namespace gssm
