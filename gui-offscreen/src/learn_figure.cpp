#include "gssm/plot/learn_figure.h"

#include <filesystem>

#include "gssm/plot/figure.h"

namespace gssm::plot {

namespace {
// A learning's trace per iteration, with a dashed line at a value to compare.
Figure traceFigure(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                   const std::vector<double>& trace, const std::string& trace_label, const std::string& level_label,
                   double level) {
  Figure fig;
  fig.title = title, fig.xlabel = xlabel, fig.ylabel = ylabel;
  fig.robust_quantile = 0;
  Series learnt{trace_label, {}, {}, paletteColor(0)};
  for (std::size_t i = 0; i < trace.size(); ++i) learnt.x.push_back(static_cast<double>(i + 1)), learnt.y.push_back(trace[i]);
  const double last = learnt.x.empty() ? 1.0 : learnt.x.back();
  fig.series.push_back(Series{level_label, {1.0, last}, {level, level}, paletteColor(1), 2, true});
  fig.series.push_back(std::move(learnt));
  return fig;
}
}  // namespace

namespace {
Figure learningFigure(const NoiseLearningReport& r, const std::string& label) {
  if (r.log_likelihood.empty() && !r.prior_expected_log_prior.empty())  // only the constants' prior, by EM
    return traceFigure(label + ": the constants' prior learnt by EM, expected log prior per E-step",
                       "E-step (batch solve)", "E[log p(x_b | sigma)] after the M-step", r.prior_expected_log_prior,
                       "learnt", "at the start sigma", r.prior_start_expected_log_prior);
  return traceFigure(label + ": noise learnt from the log, log-likelihood per iteration", (r.optimizer.empty() ? std::string("nelder-mead") : r.optimizer) + " iteration",
                     "log-likelihood (EKF prediction errors)", r.log_likelihood, "learnt (best so far)",
                     "at the INI's given values", r.given_log_likelihood);
}
}  // namespace

FigureJob learningFigureJob(const NoiseLearningReport& r, const std::string& dir, const std::string& label) {
  return {[&r, label] { return learningFigure(r, label); },
          (std::filesystem::path(dir) / "fig-learn-loglik.png").string()};
}

std::string writeLearningFigure(const NoiseLearningReport& r, const std::string& dir, const std::string& label) {
  const FigureJob job = learningFigureJob(r, dir, label);
  drawPngs({job}, 1);
  return job.path;
}

}  // namespace gssm::plot
