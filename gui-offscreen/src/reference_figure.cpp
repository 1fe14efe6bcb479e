#include <cmath>
#include <filesystem>

#include "gssm/plot/figure.h"
#include "gssm/plot/run_figures.h"

namespace gssm::plot {

namespace {
Figure constantsReferenceFigure(const Model& model, const OfflineRun& run, const Eigen::VectorXd& reference,
                                const Truth* truth, const std::string& label) {
  const int nb = model.dims().nb;
  const Gaussian xb{run.rows.back().mean.tail(nb), run.rows.back().covariance.bottomRightCorner(nb, nb)};
  const Gaussian compared = truth ? model.comparableConstants(xb, *truth) : xb;  // in the reference's terms
  const Eigen::VectorXd& mean = compared.mean;
  const Eigen::VectorXd sd = compared.covariance.diagonal().cwiseSqrt();
  Figure fig;
  fig.title = label + ": " + methodName(run.method) + " constants (band: ±2 sd) against the calibration reference";
  fig.xlabel = "constant, in the estimates' column order (" + model.names().constants.front() + " ... " +
               model.names().constants.back() + ")";
  fig.ylabel = "value";
  fig.robust_quantile = 0;
  Band band{{}, {}, {}, paletteColor(0)};
  Series est{methodName(run.method), {}, {}, paletteColor(0)}, ref{"calibration reference", {}, {}, paletteColor(1)};
  ref.dashed = true;
  for (int i = 0; i < nb; ++i) {
    if (!std::isfinite(reference[i])) continue;
    const double x = static_cast<double>(i);
    band.x.push_back(x), band.lo.push_back(mean[i] - 2 * sd[i]), band.hi.push_back(mean[i] + 2 * sd[i]);
    est.x.push_back(x), est.y.push_back(mean[i]);
    ref.x.push_back(x), ref.y.push_back(reference[i]);
  }
  fig.bands.push_back(std::move(band));
  fig.series = {std::move(est), std::move(ref)};
  return fig;
}
}  // namespace

FigureJob constantsReferenceFigureJob(const Model& model, const OfflineRun& run, const Eigen::VectorXd& reference,
                                      const Truth* truth, const std::string& dir, const std::string& label) {
  return {[&model, &run, &reference, truth, label] { return constantsReferenceFigure(model, run, reference, truth, label); },
          (std::filesystem::path(dir) / "fig-constants-vs-reference.png").string()};
}

}  // namespace gssm::plot
