#pragma once
// Robust losses on a whitened residual r (docs/DESIGN.md §9): a factor's
// cost is ½ρ(s) with s = ‖r‖² instead of ½s, so a measurement far from the
// estimate counts less (Huber, Cauchy) or not at all (Tukey). The solvers
// minimize it by iteratively reweighted least squares: at each
// linearization r and J are scaled by √ρ'(s), which keeps the gradient
// Σ ρ'(s) Jᵀr exact, so the fixed point is the robust optimum.
#include <cmath>
#include <string>

namespace gssm {

struct RobustLoss {
  enum class Kind { None, Huber, Cauchy, Tukey };
  Kind kind = Kind::None;
  /// k: where the loss departs from the square, in units of the whitened
  /// residual (noise standard deviations).
  double scale = 1.0;

  bool robust() const { return kind != Kind::None; }
  /// ρ(s), s = ‖r‖² ≥ 0.
  double rho(double s) const {
    const double k2 = scale * scale;
    switch (kind) {
      case Kind::None: return s;
      case Kind::Huber: return s <= k2 ? s : 2 * scale * std::sqrt(s) - k2;
      case Kind::Cauchy: return k2 * std::log1p(s / k2);
      case Kind::Tukey: {
        if (s >= k2) return k2 / 3;
        const double a = 1 - s / k2;
        return k2 / 3 * (1 - a * a * a);
      }
    }
    return s;
  }
  /// ρ'(s), the weight of iteratively reweighted least squares (1 without a loss).
  double weight(double s) const {
    const double k2 = scale * scale;
    switch (kind) {
      case Kind::None: return 1.0;
      case Kind::Huber: return s <= k2 ? 1.0 : scale / std::sqrt(s);
      case Kind::Cauchy: return 1.0 / (1.0 + s / k2);
      case Kind::Tukey: {
        if (s >= k2) return 0.0;
        const double a = 1 - s / k2;
        return a * a;
      }
    }
    return 1.0;
  }
  /// "none", "huber", "cauchy", "tukey".
  static const char* name(Kind k) {
    switch (k) {
      case Kind::None: return "none";
      case Kind::Huber: return "huber";
      case Kind::Cauchy: return "cauchy";
      case Kind::Tukey: return "tukey";
    }
    return "?";
  }
  /// The kind called `text` ("none", "huber", "cauchy", "tukey"); false if none is.
  static bool named(const std::string& text, Kind* kind) {
    for (Kind k : {Kind::None, Kind::Huber, Kind::Cauchy, Kind::Tukey})
      if (text == name(k)) return *kind = k, true;
    return false;
  }
  /// The usual scale of each kind: Huber's 1.345 (95% efficiency on
  /// Gaussian noise), 2.5 for Cauchy and Tukey.
  static double defaultScale(Kind k) { return k == Kind::Huber ? 1.345 : 2.5; }
  bool validate(std::string* why = nullptr) const {
    if (robust() && !(scale > 0 && std::isfinite(scale))) {
      if (why) *why = std::string("robust loss ") + name(kind) + ": scale must be > 0";
      return false;
    }
    return true;
  }
};

}  // namespace gssm
