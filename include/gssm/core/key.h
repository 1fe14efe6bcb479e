#pragma once
// Variable identifiers of a GSSM factor graph. A graph has exactly one node
// for the constant block x_b (for the whole run) and one node x_c(k) per step.
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>

namespace gssm {

enum class VariableKind : std::uint8_t { State = 0, Constants = 1 };

/// Names a variable: the time-series state at step k, or the constants.
/// Both fields in 8 bytes: a full-history run holds several keys per step
/// (factors, separators, the variable index).
struct Key {
  VariableKind kind : 1;
  std::int64_t step : 63;  ///< step index for a State (< 0: a state inserted later); 0 for Constants

  constexpr Key() : kind(VariableKind::State), step(0) {}
  constexpr Key(VariableKind k, std::int64_t s) : kind(k), step(s) {}

  static Key state(std::int64_t k) { return {VariableKind::State, k}; }
  static Key constants() { return {VariableKind::Constants, 0}; }
  bool isConstants() const { return kind == VariableKind::Constants; }

  /// Elimination-friendly order: states by step, constants last.
  friend bool operator<(const Key& a, const Key& b) {
    if (a.kind != b.kind) return a.kind < b.kind;
    return a.step < b.step;
  }
  friend bool operator==(const Key& a, const Key& b) { return a.word() == b.word(); }
  friend bool operator!=(const Key& a, const Key& b) { return !(a == b); }

  /// Both fields as one word (one load and compare instead of two masked ones).
  std::uint64_t word() const {
    std::uint64_t w;
    std::memcpy(&w, this, sizeof w);
    return w;
  }

  /// "x_c(12)" or "x_b".
  std::string toString() const {
    if (isConstants()) return "x_b (constants)";
    // Negative steps: states inserted into the chain for late measurements.
    return step < 0 ? "x_c(inserted " + std::to_string(-step) + ")" : "x_c(" + std::to_string(step) + ")";
  }
};

static_assert(sizeof(Key) == 8, "Key packs its kind and step into one word");

struct KeyHash {
  std::size_t operator()(const Key& k) const noexcept { return std::hash<std::uint64_t>()(k.word()); }
};

}  // namespace gssm
