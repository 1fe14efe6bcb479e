#include "gssm/plot/learn_figure.h"

#include <filesystem>

#include "gssm/plot/figure.h"

namespace gssm::plot {

std::string writeLearningFigure(const NoiseLearningReport& r, const std::string& dir, const std::string& label) {
  Figure fig;
  fig.title = label + ": noise learnt from the log, log-likelihood per iteration";
  fig.xlabel = "Nelder-Mead iteration";
  fig.ylabel = "log-likelihood (EKF prediction errors)";
  fig.robust_quantile = 0;
  Series learnt{"learnt (best so far)", {}, {}, paletteColor(0)};
  for (std::size_t i = 0; i < r.log_likelihood.size(); ++i)
    learnt.x.push_back(static_cast<double>(i + 1)), learnt.y.push_back(r.log_likelihood[i]);
  const double last = learnt.x.empty() ? 1.0 : learnt.x.back();
  fig.series.push_back(Series{"at the INI's given values", {1.0, last}, {r.given_log_likelihood, r.given_log_likelihood},
                              paletteColor(1), 2, true});
  fig.series.push_back(std::move(learnt));
  const std::string path = (std::filesystem::path(dir) / "fig-learn-loglik.png").string();
  savePng(fig, path);
  return path;
}

}  // namespace gssm::plot
