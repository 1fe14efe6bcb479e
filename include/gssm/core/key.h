#pragma once
// Variable identifiers of a GSSM factor graph. A graph has exactly one node
// for the constant block x_b (for the whole run) and one node x_c(k) per step.
#include <cstdint>
#include <functional>
#include <string>

namespace gssm {

enum class VariableKind : std::uint8_t { State = 0, Constants = 1 };

/// Names a variable: the time-series state at step k, or the constants.
struct Key {
  VariableKind kind = VariableKind::State;
  std::int64_t step = 0;  ///< step index for a State; 0 for Constants

  static Key state(std::int64_t k) { return {VariableKind::State, k}; }
  static Key constants() { return {VariableKind::Constants, 0}; }
  bool isConstants() const { return kind == VariableKind::Constants; }

  /// Elimination-friendly order: states by step, constants last.
  friend bool operator<(const Key& a, const Key& b) {
    if (a.kind != b.kind) return a.kind < b.kind;
    return a.step < b.step;
  }
  friend bool operator==(const Key& a, const Key& b) {
    return a.kind == b.kind && a.step == b.step;
  }
  friend bool operator!=(const Key& a, const Key& b) { return !(a == b); }

  /// "x_c(12)" or "x_b".
  std::string toString() const {
    return isConstants() ? std::string("x_b (constants)")
                         : "x_c(" + std::to_string(step) + ")";
  }
};

struct KeyHash {
  std::size_t operator()(const Key& k) const noexcept {
    return std::hash<std::uint64_t>()(static_cast<std::uint64_t>(k.step) * 2u +
                                      static_cast<std::uint64_t>(k.kind));
  }
};

}  // namespace gssm
