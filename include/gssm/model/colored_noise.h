#pragma once
// Time-correlated measurement noise on any channel of any model
// (docs/DESIGN.md §9, "Coloured noise"). A chosen channel's error is
//
//   r(k) = e(k) + w(k),   e(k+1) = φ·e(k) + q(k),   φ = exp(−dt/τ),
//   q ~ N(0, σ²(1 − φ²)),  e(0) ~ N(0, σ²)  (stationary),  w ~ N(0, R),
//
// a first-order Gauss–Markov part e per component plus the channel's white
// R. By state augmentation (Bryson–Henrikson's measurement differencing
// needs every channel sampled at one regular rate and correlates the
// differenced noise with the process noise; appended states need neither,
// and work with asynchronous channels and out-of-sequence data): e is
// appended to x_c, so every method handles it unchanged, and τ and σ are
// noise parameters that learning fits like any σ.
//
// Every registered model type takes it from [colored_noise] (the registry
// adds the keys and wraps the model; docs/DESIGN.md §3):
//
//   [colored_noise]
//   channels = all        ; or channel names
//   tau = 0.3             ; correlation time (s)
//   sd = 0.05             ; stationary σ of e, in the channel's unit
#include <memory>
#include <string>
#include <vector>

#include "gssm/model/model.h"
#include "gssm/model/params.h"

namespace gssm {

struct ColoredNoise {
  /// The channels with a Gauss–Markov part: names, or {"all"}; empty: none
  /// (white noise, the model unwrapped).
  std::vector<std::string> channels;
  double tau = 1.0;  ///< correlation time τ (s), > 0
  double sd = 0.1;   ///< stationary σ of e, > 0
  bool enabled() const { return !channels.empty(); }
};

/// [colored_noise] channels, tau and sd (tau and sd learnable).
std::vector<ParamSpec> coloredNoiseParams();
/// Reads [colored_noise]; disabled when `channels` is not given.
ColoredNoise readColoredNoise(const ParamSource& in);
/// Writes it (nothing when disabled).
void writeColoredNoise(const ColoredNoise& noise, ParamSink& out);

/// `inner` with a Gauss–Markov error on the chosen channels (itself when
/// `noise` is disabled). The error states are named err_<component>
/// (err_<channel>_<component> on a channel of several). InvalidArgument
/// naming an unknown channel and the known ones, or a τ or σ not > 0.
std::unique_ptr<Model> withColoredNoise(std::unique_ptr<Model> inner, const ColoredNoise& noise);
/// The model `model` wraps, or `model` itself if it has no coloured noise.
const Model& withoutColoredNoise(const Model& model);
/// Its coloured noise; null for a model without.
const ColoredNoise* coloredNoiseOf(const Model& model);

}  // namespace gssm
