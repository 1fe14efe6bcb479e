#pragma once
// The figure of a noise learning (docs/DESIGN.md §10): the log-likelihood
// per iteration, with the hand-given values' likelihood for comparison; when
// only the constants' prior was learnt, EM's expected log prior per E-step.
#include <string>

#include "gssm/learn/noise_learning.h"
#include "gssm/plot/figure.h"

namespace gssm::plot {

/// dir/fig-learn-loglik.png, to draw (drawPngs); `report` must outlive it.
FigureJob learningFigureJob(const NoiseLearningReport& report, const std::string& dir, const std::string& label);
/// Writes dir/fig-learn-loglik.png; returns its path.
std::string writeLearningFigure(const NoiseLearningReport& report, const std::string& dir, const std::string& label);

}  // namespace gssm::plot
