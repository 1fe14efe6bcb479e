#include "gssm/plot/learn_figure.h"

#include <filesystem>

#include "gssm/plot/figure.h"

namespace gssm::plot {

namespace {
// Only the constants' prior was learnt: EM's expected log prior per E-step.
Figure emFigure(const NoiseLearningReport& r, const std::string& label) {
  Figure fig;
  fig.title = label + ": the constants' prior learnt by EM, expected log prior per E-step";
  fig.xlabel = "E-step (batch solve)";
  fig.ylabel = "E[log p(x_b | sigma)] after the M-step";
  fig.robust_quantile = 0;
  Series em{"learnt", {}, {}, paletteColor(0)};
  for (std::size_t i = 0; i < r.prior_expected_log_prior.size(); ++i)
    em.x.push_back(static_cast<double>(i + 1)), em.y.push_back(r.prior_expected_log_prior[i]);
  const double last = em.x.empty() ? 1.0 : em.x.back();
  fig.series.push_back(Series{"at the start sigma", {1.0, last},
                              {r.prior_start_expected_log_prior, r.prior_start_expected_log_prior}, paletteColor(1), 2,
                              true});
  fig.series.push_back(std::move(em));
  return fig;
}

Figure likelihoodFigure(const NoiseLearningReport& r, const std::string& label) {
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
  return fig;
}
}  // namespace

std::string writeLearningFigure(const NoiseLearningReport& r, const std::string& dir, const std::string& label) {
  const bool em_only = r.log_likelihood.empty() && !r.prior_expected_log_prior.empty();
  const std::string path = (std::filesystem::path(dir) / "fig-learn-loglik.png").string();
  savePng(em_only ? emFigure(r, label) : likelihoodFigure(r, label), path);
  return path;
}

}  // namespace gssm::plot
