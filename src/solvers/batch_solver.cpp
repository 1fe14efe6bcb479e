#include "gssm/solvers/batch_solver.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>

#include "gssm/core/error.h"
#include "gssm/core/parallel.h"
#include "linear/envelope_cholesky.h"
#include "linear/normal_equations.h"
#include "linear/sparse_cholesky.h"
#include "solvers/anderson.h"
#include "solvers/change_step.h"
#include "solvers/damping.h"
#include "solvers/newton.h"

namespace gssm {

namespace {
// The next states' factors add to the same columns of H a few rows further
// down: a long chain's constants columns (one per link on UWB, 650 KB each)
// are ~25 streams at once, more than the hardware prefetcher follows, so
// their next lines are asked for ahead (16 rows: ~3 states of 6). A hint: it
// never faults, and past the envelope's end it loads nothing needed.
inline void prefetchRowsAhead(const double* entry) {
  __builtin_prefetch(reinterpret_cast<const void*>(reinterpret_cast<std::uintptr_t>(entry) + 16 * sizeof(double)), 1);
}
}  // namespace

const char* BatchSolverOptions::methodName(Method m) {
  return m == Method::GaussNewton ? "gauss-newton" : "levenberg-marquardt";
}

std::optional<BatchSolverOptions::Method> BatchSolverOptions::methodNamed(const std::string& name) {
  for (auto m : {Method::LevenbergMarquardt, Method::GaussNewton})
    if (name == methodName(m)) return m;
  return std::nullopt;
}

bool BatchSolverOptions::validate(std::string* why) const {
  auto fail = [&](const std::string& msg) {
    if (why) *why = "BatchSolverOptions: " + msg;
    return false;
  };
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(relative_cost_tolerance >= 0)) return fail("relative_cost_tolerance must be >= 0");
  if (!(step_tolerance >= 0)) return fail("step_tolerance must be >= 0");
  if (!(gradient_tolerance >= 0)) return fail("gradient_tolerance must be >= 0");
  if (!(decrease_tolerance >= 0)) return fail("decrease_tolerance must be >= 0");
  if (!(initial_lambda > 0)) return fail("initial_lambda must be > 0");
  if (!(max_lambda > initial_lambda)) return fail("max_lambda must exceed initial_lambda");
  if (newton_polish_steps < 0) return fail("newton_polish_steps must be >= 0");
  if (threads < 1) return fail("threads must be >= 1, got " + std::to_string(threads));
  if (anderson_memory < 0 || anderson_memory > 16)
    return fail("anderson_memory must be 0 (off) to 16, got " + std::to_string(anderson_memory));
  if (!relinearize_at_solution && newton_polish_steps > 0)
    return fail("relinearize_at_solution = false needs no Newton polish (the polish relinearizes at the solution)");
  return true;
}

const char* toString(BatchSolverSummary::Termination t) {
  using T = BatchSolverSummary::Termination;
  switch (t) {
    case T::CostConverged: return "cost converged";
    case T::StepConverged: return "step converged";
    case T::GradientConverged: return "gradient converged";
    case T::MaxIterations: return "iteration limit reached";
    case T::NoProgress: return "no progress (damping at its maximum)";
  }
  return "?";
}

std::string BatchSolverSummary::toString() const {
  std::ostringstream os;
  os << "BatchSolver: " << gssm::toString(termination) << " after " << iterations
     << " iterations (" << rejected_steps << " rejected, " << factorizations << " factorizations"
     << (linear_solver.empty() ? std::string() : ", " + linear_solver + " Cholesky")
     << (newton_steps ? ", " + std::to_string(newton_steps) + " Newton" : std::string())
     << (anderson_steps || anderson_rejected
             ? ", " + std::to_string(anderson_steps) + " Anderson-mixed (" + std::to_string(anderson_rejected) + " refused)"
             : std::string())
     << "), cost " << initial_cost << " -> " << final_cost
     << ", max|gradient| " << gradient_norm << ", " << num_variables << " variables / "
     << num_factors << " factors / dim " << dimension << ", " << seconds << " s";
  return os.str();
}

// The linearized system of one graph. setup() lays out, from the keys and
// sizes alone, each factor's columns and where each entry of its JᵀJ lands
// in H's compressed columns; every linearization then writes H in place
// (no triplets, no key lookups, no re-sorting).
struct BatchSolver::Impl {
  struct Iteration;  // one solve's LM iteration (below)
  std::vector<Key> layout;               // the variables' keys in column order (Key order)
  std::vector<Eigen::Index> offset;      // first column of each, by Values position; then n
  Eigen::Index n = 0;
  // H is factored by its envelope where that is compact — a chain of
  // states with the constants last: no entry lists, no symbolic analysis,
  // an entry's place found by arithmetic — and by CHOLMOD otherwise.
  bool use_envelope = false;
  internal::EnvelopeCholesky envelope;
  internal::SparseCholesky chol;
  // Compact (a million-step run has 2M factors): each factor's variables as
  // positions in the layout, concatenated; factor i's are
  // factor_vars[factor_begin[i] ...].
  std::vector<std::uint32_t> factor_vars;
  std::vector<std::uint32_t> factor_begin;
  const int* entry_slot = nullptr;        // H's value index of every JᵀJ entry, factor by factor (chol's)
  const int* diagonal_slot = nullptr;     // H(i, i)'s value index
  std::vector<std::uint32_t> factor_shape;  // index into a Scratch's jacobians (same keys count and residual size)
  // One thread's buffers for linearizing a run of factors: Jacobians per
  // factor shape (alternating process and measurement factors reuse their
  // storage), a factor's variables' values, first columns and reachable
  // columns (Factor::columnsOf), its gathered columns and residual.
  struct Scratch {
    std::vector<std::vector<Eigen::MatrixXd>> jacobians;
    std::vector<const Eigen::VectorXd*> x;
    std::vector<Eigen::Index> offs;
    std::vector<const std::vector<int>*> used;
    internal::FactorColumns columns;
    Eigen::VectorXd r;
    void size(std::size_t shapes, std::size_t max_keys) {
      jacobians.clear();
      jacobians.resize(shapes);
      x.resize(max_keys);
      offs.resize(max_keys);
      used.resize(max_keys);
    }
  };
  Scratch scratch[2];  // [1]: the second part of a split linearization
  // A long chain (kSplitFactors factors or more, on the envelope) is
  // linearized in two halves of its factors, on two threads where the
  // options allow. The halves write disjoint entries of H and g except
  // those among the columns both reach (a chain's middle state and the
  // constants): the second half sums these apart, added after both — the
  // same order, so the same bits, with one thread or two.
  struct Split {
    std::size_t at = 0;                 // the second half's first factor; 0: not split
    std::vector<int> shared;            // by column: its index among the shared columns, or −1
    std::vector<Eigen::Index> columns;  // the shared columns, ascending
    Eigen::MatrixXd side_h;             // the second half's JᵀJ among them (upper triangle)
    Eigen::VectorXd side_g;             // and its gradient there
  } split;
  static constexpr std::size_t kSplitFactors = 16384, kMaxSharedColumns = 256;
  int threads = 1;
  bool has_solution = false;
  Eigen::VectorXd factored_point;  // where H was last factored, flat in the layout
  Eigen::VectorXd factored_gradient;  // g = Jᵀr there (stepAfterChange)
  double factored_cost = 0;           // ½Σ‖r‖² there
  internal::Retraction retraction;    // the last graph's x ⊕ δ
  Eigen::VectorXd change_backup;      // stepAfterChange's values before it
  internal::LocalChange change;       // and its buffers, reused
  internal::LowRankCorrection correction;
  // H⁻¹ on the factor's pattern, computed on the first covariance query.
  mutable std::optional<internal::SparseCholesky::SelectedInverse> selected;
  mutable bool envelope_inverse = false;  // envelope.selectedInverse() done for this solution
  mutable bool envelope_block_used = false;  // envelope.inverseBlock() answered once for this solution

  // A new graph: no solution yet; the variables' layout, each factor's
  // variables and shape, then the linear solver for the graph's pattern.
  void setup(const FactorGraph& graph, const Values& values, int thread_count) {
    has_solution = false;
    selected.reset();
    threads = thread_count;
    layoutVariables(values);
    indexFactors(graph, values);
    if (!chooseEnvelope(graph)) assembleSparsePattern(graph);
    chooseSplit(graph);
  }

  void layoutVariables(const Values& values) {
    offset.clear();
    layout.clear();
    layout.reserve(values.size());
    n = 0;
    for (const auto& kv : values) {  // Key order: states by step, constants last
      offset.push_back(n);
      layout.push_back(kv.first);
      n += kv.second.size();
    }
    offset.push_back(n);
  }

  void indexFactors(const FactorGraph& graph, const Values& values) {
    factor_vars.clear();
    factor_begin.assign(1, 0);
    factor_shape.clear();
    // Few distinct shapes (process, measurement, prior): a short list, not a map.
    std::vector<std::pair<std::pair<std::size_t, int>, std::uint32_t>> shapes;
    factor_vars.reserve(3 * graph.size());
    factor_begin.reserve(graph.size() + 1);
    factor_shape.reserve(graph.size());
    std::size_t max_keys = 0;
    for (const auto& f : graph) {
      for (const auto& k : f->keys()) {
        std::size_t i = 0;
        try {  // one lookup per key (a million-step run has 5M)
          i = values.indexOf(k);
        } catch (const InvalidArgument&) {
          throw InvalidArgument("BatchSolver: factor '" + f->describe() + "' uses " + k.toString() +
                                ", which has no initial value");
        }
        factor_vars.push_back(static_cast<std::uint32_t>(i));
      }
      factor_begin.push_back(static_cast<std::uint32_t>(factor_vars.size()));
      max_keys = std::max(max_keys, f->keys().size());
      const auto key = std::make_pair(f->keys().size(), f->dim());
      auto shape = std::find_if(shapes.begin(), shapes.end(), [&](const auto& e) { return e.first == key; });
      if (shape == shapes.end()) shape = shapes.insert(shapes.end(), {key, static_cast<std::uint32_t>(shapes.size())});
      factor_shape.push_back(shape->second);
    }
    for (Scratch& s : scratch) s.size(shapes.size(), max_keys);
  }

  // The halves of a long chain and the columns both reach (Split); a graph
  // whose halves share many columns (no chain) stays whole.
  void chooseSplit(const FactorGraph& graph) {
    split.at = 0;
    split.shared.clear();
    split.columns.clear();
    if (!use_envelope || graph.size() < kSplitFactors) return;
    const std::size_t at = graph.size() / 2;
    std::vector<std::uint8_t> half(layout.size(), 0);  // bit 1: the first half reaches it, bit 2: the second
    for (std::size_t fi = 0; fi < graph.size(); ++fi)
      for (std::size_t k = factor_begin[fi]; k < factor_begin[fi + 1]; ++k) half[factor_vars[k]] |= fi < at ? 1 : 2;
    std::vector<Eigen::Index> columns;
    for (std::size_t v = 0; v < layout.size(); ++v)
      if (half[v] == 3)
        for (Eigen::Index j = offset[v]; j < offset[v + 1]; ++j) columns.push_back(j);
    if (columns.size() > kMaxSharedColumns) return;
    split.shared.assign(static_cast<std::size_t>(n), -1);
    for (std::size_t a = 0; a < columns.size(); ++a) split.shared[static_cast<std::size_t>(columns[a])] = static_cast<int>(a);
    split.columns = std::move(columns);
    const auto k = static_cast<Eigen::Index>(split.columns.size());
    split.side_h.resize(k, k);
    split.side_g.resize(k);
    split.at = at;
  }

  // The envelope: each column's first row reached by a factor. Compact (at
  // most twice the entries factors add, plus the diagonal) for a chain in
  // time order with the constants last, small or large (a paper window of 10
  // steps: 1.4× faster than the dense factorization of its 14 unknowns);
  // SparseCholesky for any other graph (dense up to 64 unknowns, CHOLMOD
  // beyond). True when the envelope is used.
  bool chooseEnvelope(const FactorGraph& graph) {
    // Every column of a factor's variables gets the factor's lowest column
    // as a first row (it is ≤ each of them): one minimum per variable, not
    // per column (a range reaches 30 columns through two variables).
    std::vector<Eigen::Index> low(layout.size(), n);  // lowest column of any factor on the variable
    std::size_t added = 0;
    for (std::size_t fi = 0; fi < graph.size(); ++fi) {
      const std::size_t b = factor_begin[fi], count = factor_begin[fi + 1] - b;
      Eigen::Index lowest = n, prev = -1, m = 0;
      bool ascending = true;
      for (std::size_t a = 0; a < count; ++a) {
        const std::uint32_t v = factor_vars[b + a];
        const Eigen::Index o = offset[v], d = offset[v + 1] - o;
        if (d == 0) continue;
        if (o <= prev) ascending = false;  // a repeated column: its pairs counted one by one
        prev = o + d - 1;
        lowest = std::min(lowest, o);
        m += d;
      }
      for (std::size_t a = 0; a < count; ++a) {
        Eigen::Index& l = low[factor_vars[b + a]];
        l = std::min(l, lowest);
      }
      if (ascending) {
        added += static_cast<std::size_t>(m * (m + 1) / 2);
      } else {
        placeColumns(fi);
        internal::forEachUpperPair(scratch[0].columns, [&](std::size_t, std::size_t) { ++added; });
      }
    }
    std::vector<int> first(static_cast<std::size_t>(n));
    std::size_t size = 0;
    for (std::size_t v = 0; v < layout.size(); ++v)
      for (Eigen::Index j = offset[v]; j < offset[v + 1]; ++j) {
        first[static_cast<std::size_t>(j)] = static_cast<int>(std::min(j, low[v]));
        size += static_cast<std::size_t>(j - first[static_cast<std::size_t>(j)] + 1);
      }
    use_envelope = n > 0 && size <= 2 * added + static_cast<std::size_t>(n);
    if (use_envelope) {
      chol.reset(0, 0);  // a previous graph's pattern and factor go
      envelope.setPattern(std::move(first));
      entry_slot = diagonal_slot = nullptr;
      return true;
    }
    envelope = internal::EnvelopeCholesky();
    return false;
  }

  // The pattern: every factor's upper JᵀJ entries, then the diagonal (which
  // the damping needs even where no factor reaches).
  void assembleSparsePattern(const FactorGraph& graph) {
    std::size_t entries = 0;
    chol.assemblePattern(n, [&](auto&& emit) {
      entries = 0;
      forEachFactorEntry(graph.size(), [&](Eigen::Index i, Eigen::Index j) {
        emit(i, j);
        ++entries;
      });
      for (Eigen::Index i = 0; i < n; ++i) emit(i, i);
    });
    entry_slot = chol.slots();
    diagonal_slot = entry_slot + entries;
  }

  // emit(i, j) for every upper-triangle entry (i <= j) of every factor's
  // JᵀJ, factor by factor, in the order linearize() fills them.
  template <class Emit>
  void forEachFactorEntry(std::size_t factors, Emit&& emit) {
    for (std::size_t fi = 0; fi < factors; ++fi) {
      placeColumns(fi);
      const internal::FactorColumns& columns = scratch[0].columns;
      internal::forEachUpperPair(columns,
                                 [&](std::size_t p, std::size_t q) { emit(columns.global[p], columns.global[q]); });
    }
  }

  static constexpr std::size_t npos = static_cast<std::size_t>(-1);
  // Position of k in the layout, or npos (consecutive steps: found directly).
  std::size_t positionOf(const Key& k) const {
    if (layout.empty()) return npos;
    const Key& first = layout.front();
    if (!first.isConstants() && !k.isConstants() && k.step >= first.step) {
      const auto guess = static_cast<std::size_t>(k.step - first.step);
      if (guess < layout.size() && layout[guess] == k) return guess;
    }
    const auto it = std::lower_bound(layout.begin(), layout.end(), k);
    return it != layout.end() && *it == k ? static_cast<std::size_t>(it - layout.begin()) : npos;
  }

  // Factor fi's columns of H into scratch[0].columns (a pattern: no entries).
  void placeColumns(std::size_t fi) {
    Scratch& s = scratch[0];
    const std::size_t b = factor_begin[fi], count = factor_begin[fi + 1] - b;
    for (std::size_t a = 0; a < count; ++a) s.offs[a] = offset[factor_vars[b + a]];
    s.columns.place(s.offs.data(), count, [&](std::size_t a) {
      const std::size_t v = factor_vars[b + a];
      return offset[v + 1] - offset[v];
    });
  }

  // Linearizes every factor at x: writes H = JᵀJ into the factorization's
  // values (undamped; `diag` gets its diagonal), the gradient g = Jᵀr, and
  // returns the cost. A non-finite residual throws, or with `trial` (an LM
  // candidate) returns +∞, leaving H to be rewritten at the previous point.
  double linearize(const FactorGraph& graph, const Values& x, Eigen::VectorXd& g,
                   Eigen::VectorXd& diag, bool trial = false) {
    g.setZero(n);
    double* H = use_envelope ? envelope.values() : chol.values();
    std::fill(H, H + (use_envelope ? envelope.entries() : chol.nonzeros()), 0.0);
    RangeResult half[2];
    std::vector<std::exception_ptr> errors;  // a split's, by half (none allocated for one part: a window's solves)
    if (split.at == 0) {
      half[0] = linearizeRange<false>(graph, x, 0, graph.size(), scratch[0], H, g.data());
    } else {
      split.side_h.setZero();
      split.side_g.setZero();
      errors = runJobs(2, static_cast<std::size_t>(threads), [&](std::size_t k) {
        half[k] = k == 0 ? linearizeRange<false>(graph, x, 0, split.at, scratch[0], H, g.data())
                         : linearizeRange<true>(graph, x, split.at, graph.size(), scratch[1], H, g.data());
      });
    }
    for (std::size_t k = 0; k < 2; ++k) {  // in factor order: what one pass would have met first
      if (k < errors.size() && errors[k]) std::rethrow_exception(errors[k]);
      if (half[k].bad == npos) continue;
      if (trial) return std::numeric_limits<double>::infinity();
      throw NumericalError("BatchSolver: factor '" + graph[half[k].bad]->describe() +
                           "' has a non-finite residual at the current estimate");
    }
    if (split.at != 0) addSharedEntries(H, g.data());
    diag.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) diag[i] = H[diagonalOf(i)];
    return half[0].cost + half[1].cost;
  }

  struct RangeResult {
    double cost = 0;
    std::size_t bad = npos;  // the first factor with a non-finite residual (it stopped there)
  };
  // Factors [begin, end) into H and g (kSecond: the second half of a split,
  // its entries among the shared columns into split.side_h/side_g).
  template <bool kSecond>
  RangeResult linearizeRange(const FactorGraph& graph, const Values& x, std::size_t begin, std::size_t end,
                             Scratch& s, double* H, double* g) {
    RangeResult out;
    const int* slot = entry_slot;  // CHOLMOD's order: the whole graph, one part
    const auto first = x.begin();  // positions are the layout's (x has values' keys)
    for (std::size_t fi = begin; fi < end; ++fi) {
      const Factor& f = *graph[fi];
      std::vector<Eigen::MatrixXd>& J = s.jacobians[factor_shape[fi]];
      const std::size_t b = factor_begin[fi], count = factor_begin[fi + 1] - b;
      for (std::size_t a = 0; a < count; ++a) {  // its variables' values and first columns
        const std::uint32_t v = factor_vars[b + a];
        s.x[a] = &(first + v)->second;
        s.offs[a] = offset[v];
      }
      const double c = f.linearizeRobustAt(s.x.data(), s.r, &J);  // reweighted at every linearization
      if (!s.r.allFinite()) {
        out.bad = fi;
        return out;
      }
      out.cost += c;
      // The envelope places entries by position, so a block's columns the
      // factor rules out need not be read; CHOLMOD's slots follow every
      // column in order.
      if (use_envelope) {
        for (std::size_t a = 0; a < count; ++a) s.used[a] = f.columnsOf(a);
        s.columns.gather(s.offs.data(), J, s.used.data());
        const auto shared = [&](Eigen::Index i) { return kSecond ? split.shared[static_cast<std::size_t>(i)] : -1; };
        internal::forEachNonzeroGradientAndUpperJtJ(
            s.columns, s.r.data(),
            [&](Eigen::Index i, double v) {
              const int p = shared(i);
              if (p >= 0) split.side_g[p] += v;
              else g[i] += v;
            },
            [&](Eigen::Index i, Eigen::Index j, double v, auto...) {
              const int p = shared(i), q = shared(j);
              if (p >= 0 && q >= 0) {
                split.side_h(p, q) += v;
              } else {
                double* entry = H + envelope.position(i, j);
                prefetchRowsAhead(entry);
                *entry += v;
              }
            });
      } else {
        s.columns.gather(s.offs.data(), J);
        for (std::size_t p : s.columns.nonzero) g[s.columns.global[p]] += s.columns.dot(p, s.r.data());  // zero columns add 0
        internal::forEachUpperJtJ(s.columns, [&](Eigen::Index, Eigen::Index, double v, auto...) { H[*slot++] += v; });
      }
    }
    return out;
  }
  // The second half's sums among the shared columns, added after the first
  // half's (an entry it summed is inside the envelope: a factor reached it).
  void addSharedEntries(double* H, double* g) const {
    const auto k = static_cast<Eigen::Index>(split.columns.size());
    for (Eigen::Index q = 0; q < k; ++q) {
      g[split.columns[static_cast<std::size_t>(q)]] += split.side_g[q];
      for (Eigen::Index p = 0; p <= q; ++p)
        if (split.side_h(p, q) != 0.0)
          H[envelope.position(split.columns[static_cast<std::size_t>(p)], split.columns[static_cast<std::size_t>(q)])] +=
              split.side_h(p, q);
    }
  }
  const char* linearSolver() const {
    return use_envelope ? "envelope" : n <= internal::SparseCholesky::kDenseMax ? "dense" : "sparse";
  }
  // Where H(i, i) lives in the factorization's values.
  std::size_t diagonalOf(Eigen::Index i) const {
    return use_envelope ? envelope.diagonal(i) : static_cast<std::size_t>(diagonal_slot[i]);
  }
  Eigen::Index factorize() {
    selected.reset();
    envelope_inverse = envelope_block_used = false;
    return use_envelope ? envelope.factorize() : chol.factorize();
  }
  void solveInPlace(Eigen::VectorXd& b) {
    if (use_envelope) envelope.solveInPlace(b);
    else chol.solveInPlace(b);
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) { return use_envelope ? envelope.solve(B) : chol.solve(B); }
  // H⁻¹(i, j) if the selected inverse holds it (computed on the first call).
  bool inverseEntry(Eigen::Index i, Eigen::Index j, double& out) const {
    if (use_envelope) {  // the sweep goes up only as far as the rows asked for
      const Eigen::Index row = std::min(i, j);
      if (!envelope_inverse || row < envelope.inverseFrom()) {
        const_cast<internal::EnvelopeCholesky&>(envelope).selectedInverse(std::max<Eigen::Index>(row, 0));
        envelope_inverse = true;
      }
      return envelope.inverseEntry(i, j, out);
    }
    if (!selected) selected = const_cast<internal::SparseCholesky&>(chol).selectedInverse();
    return selected->lookup(i, j, out);
  }

  // The factor from J's rows at x instead of H's (BatchSolverOptions::
  // covariance_by_qr): every factor's reweighted rows, in the graph's
  // order (a chain's time order: each row rotates only through the band
  // above it). On the envelope only; `diag`: H's diagonal, to name a
  // column that has no pivot.
  void factorByRows(const FactorGraph& graph, const Values& x, const Eigen::VectorXd& diag) {
    selected.reset();
    envelope_inverse = envelope_block_used = false;
    Scratch& s = scratch[0];
    const auto first = x.begin();
    std::vector<std::pair<int, double>> row;
    std::vector<int> cols;
    std::vector<double> vals;
    envelope.beginRows();
    for (std::size_t fi = 0; fi < graph.size(); ++fi) {
      const Factor& f = *graph[fi];
      std::vector<Eigen::MatrixXd>& J = s.jacobians[factor_shape[fi]];
      const std::size_t b = factor_begin[fi], count = factor_begin[fi + 1] - b;
      for (std::size_t a = 0; a < count; ++a) {
        s.x[a] = &(first + factor_vars[b + a])->second;
        s.offs[a] = offset[factor_vars[b + a]];
      }
      f.linearizeRobustAt(s.x.data(), s.r, &J);
      for (Eigen::Index i = 0; i < s.r.size(); ++i) {
        row.clear();
        for (std::size_t a = 0; a < count; ++a) {
          const Eigen::Index o = s.offs[a];
          const auto add = [&](Eigen::Index c) {
            if (J[a](i, c) != 0.0) row.emplace_back(static_cast<int>(o + c), J[a](i, c));
          };
          if (const std::vector<int>* used = f.columnsOf(a)) for (int c : *used) add(c);
          else for (Eigen::Index c = 0; c < J[a].cols(); ++c) add(c);
        }
        std::sort(row.begin(), row.end());  // a factor's variables need not ascend
        cols.clear(), vals.clear();
        for (const auto& [c, v] : row) cols.push_back(c), vals.push_back(v);
        envelope.addRow(cols.data(), vals.data(), static_cast<int>(cols.size()));
      }
    }
    const Eigen::Index bad = envelope.finishRows();
    if (bad >= 0) throwSingular(bad, diag);
  }

  // H's diagonal = its undamped value (diag) + λ·max(diag, 1e-12).
  void setDamping(const Eigen::VectorXd& diag, double lambda) {
    double* H = use_envelope ? envelope.values() : chol.values();
    for (Eigen::Index i = 0; i < n; ++i) H[diagonalOf(i)] = diag[i] + lambda * std::max(diag[i], 1e-12);
  }

  // Global columns of the change's local keys: the dropped ones' and the others'.
  void changeColumns(const internal::LocalChange& c, std::vector<Eigen::Index>& dropped,
                     std::vector<Eigen::Index>& touched) const {
    for (std::size_t i = 0; i < c.keys.size(); ++i) {
      const std::size_t p = positionOf(c.keys[i]);
      for (Eigen::Index j = offset[p]; j < offset[p + 1]; ++j) (i < c.dropped ? dropped : touched).push_back(j);
    }
  }
  // δ = −(S + P·E·Pᵀ)⁻¹g' by Woodbury (batch_solver.h, stepAfterChange), in
  // the layout's columns, zero on the dropped ones: with S⁻¹v = (H⁻¹[v; 0])_R
  // and C = PᵀS⁻¹P (H⁻¹ on the touched columns), δ = −S⁻¹(g' − P·E·w),
  // w = (I + C·E)⁻¹PᵀS⁻¹g': two solves with H's factor.
  Eigen::VectorXd changedStep(const internal::LocalChange& c, const internal::LowRankCorrection& e,
                              double& predicted) {
    std::vector<Eigen::Index> ocol, tcol;
    changeColumns(c, ocol, tcol);
    const auto k = static_cast<Eigen::Index>(tcol.size());
    const Eigen::MatrixXd C = inverseAmong(tcol);
    Eigen::VectorXd g = factored_gradient;  // g' on R, 0 on O
    for (Eigen::Index a = 0; a < k; ++a) g[tcol[static_cast<std::size_t>(a)]] += e.gradient_change[a];
    for (Eigen::Index j : ocol) g[j] = 0.0;
    Eigen::VectorXd v = g;
    solveInPlace(v);  // (S⁻¹g')_R
    Eigen::VectorXd w(k);
    for (Eigen::Index a = 0; a < k; ++a) w[a] = v[tcol[static_cast<std::size_t>(a)]];
    // (I + C·E)⁻¹ = (C⁻¹ + E)⁻¹C⁻¹, where C⁻¹ + E is the changed information
    // on the touched columns once the rest is eliminated: positive definite
    // exactly when the changed graph's is.
    const Eigen::LLT<Eigen::MatrixXd> c_llt(C);
    const Eigen::MatrixXd C_inv = c_llt.solve(Eigen::MatrixXd::Identity(k, k));
    const Eigen::MatrixXd K = C_inv + e.E;
    const Eigen::LLT<Eigen::MatrixXd> k_llt(K);
    if (k > 0 && (c_llt.info() != Eigen::Success || !internal::clearlyPositiveDefinite(k_llt, K))) throwChangedSingular(c);
    const Eigen::VectorXd Ew = e.E * k_llt.solve(C_inv * w);
    v = g;
    for (Eigen::Index a = 0; a < k; ++a) v[tcol[static_cast<std::size_t>(a)]] -= Ew[a];
    solveInPlace(v);
    for (Eigen::Index j : ocol) v[j] = 0.0;
    v = -v;
    predicted = -0.5 * g.dot(v);
    if (!v.allFinite() || predicted < 0) throwChangedSingular(c);
    return v;
  }
  // H⁻¹ among the given columns.
  Eigen::MatrixXd inverseAmong(const std::vector<Eigen::Index>& columns) {
    if (use_envelope) return envelope.inverseColumns(columns);
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(columns.size()));
    for (std::size_t a = 0; a < columns.size(); ++a) E(columns[a], static_cast<Eigen::Index>(a)) = 1.0;
    const Eigen::MatrixXd X = solve(E);
    Eigen::MatrixXd out(E.cols(), E.cols());
    for (std::size_t a = 0; a < columns.size(); ++a) out.row(static_cast<Eigen::Index>(a)) = X.row(columns[a]);
    return 0.5 * (out + out.transpose());
  }
  [[noreturn]] static void throwChangedSingular(const internal::LocalChange& c) {
    std::ostringstream os;
    os << "BatchSolver::stepAfterChange: after the change the information matrix is singular or not positive "
          "definite on ";
    for (std::size_t i = c.dropped; i < c.keys.size(); ++i) os << (i > c.dropped ? ", " : "") << c.keys[i].toString();
    os << ": the remaining factors and the added ones do not determine them (add a prior there)";
    throw NumericalError(os.str());
  }

  // A weakly held variable's pivot can be ~1e-8 of its JᵀJ diagonal (the
  // GNSS/INS drive's last state inside an outage: ~1 against 4e7); where a
  // column eliminated before it is this much stiffer, that column's
  // rounding (2.2e-16 of it) is the pivot's size, and a determined variable
  // can fail to factor.
  static constexpr double kStiffRatio = 1e8;
  // The variable holding a column of H: the last offset at or before it.
  std::pair<Key, Eigen::Index> variableAt(Eigen::Index column) const {
    const std::size_t v = static_cast<std::size_t>(std::upper_bound(offset.begin(), offset.end(), column) - offset.begin()) - 1;
    return {layout[v], column - offset[v]};
  }
  // Names the variable at `column` of H and why it may not factor, from
  // JᵀJ's diagonal (`diagonal`, undamped): its own, and the nearest column
  // eliminated before it that is kStiffRatio times stiffer.
  [[noreturn]] void throwSingular(Eigen::Index column, const Eigen::VectorXd& diagonal) const {
    const auto [k, component] = variableAt(column);
    std::ostringstream os;
    os << "BatchSolver: the information matrix is not positive definite at variable " << k.toString()
       << " component " << component << (k.isConstants() ? " (a constant)" : " (a time-series state)");
    const double d = column < diagonal.size() ? diagonal[column] : NAN;
    Eigen::Index stiff = std::min(column, diagonal.size()) - 1;  // the nearest such column before it
    while (stiff >= 0 && !(diagonal[stiff] >= kStiffRatio * d)) --stiff;
    if (d == 0) {
      os << ": nothing measures it (its column of J is zero: unobserved, or a zero Jacobian such as a range at "
            "x = h = 0). Add a prior on it or check the model.";
    } else if (stiff >= 0) {
      const auto [sk, sc] = variableAt(stiff);
      os << ": the data and priors may not determine it (a combination of variables they cannot separate), or "
            "rounding lost what does: its JᵀJ diagonal is " << d << ", and " << sk.toString() << " component "
         << sc << ", eliminated before it, has " << diagonal[stiff] << " (states a fraction of a millisecond apart, or a "
            "tiny σ). Add a prior on it, check the model, or space the states further apart.";
    } else {
      os << ": the data and priors do not determine it (unobserved, a combination of variables they cannot "
            "separate, or a non-finite value). Add a prior on it or check the model.";
    }
    throw NumericalError(os.str());
  }
};

BatchSolver::BatchSolver(BatchSolverOptions options)
    : options_(options), impl_(std::make_unique<Impl>()) {
  std::string why;
  if (!options_.validate(&why)) throw InvalidArgument(why);
}
BatchSolver::~BatchSolver() = default;
BatchSolver::BatchSolver(BatchSolver&&) noexcept = default;
BatchSolver& BatchSolver::operator=(BatchSolver&&) noexcept = default;

namespace {
using Termination = BatchSolverSummary::Termination;
bool isConverged(Termination t) {
  return t == Termination::CostConverged || t == Termination::StepConverged || t == Termination::GradientConverged;
}
}  // namespace

// The Levenberg–Marquardt iteration (docs/DESIGN.md §5, eq. 6) of one solve:
// its iterate (in the caller's Values), gradient, diagonal and cost.
struct BatchSolver::Impl::Iteration {
  Impl& s;
  const BatchSolverOptions& options;
  const FactorGraph& graph;
  Values& x;
  BatchSolverSummary& sum;
  const bool lm = options.method == BatchSolverOptions::Method::LevenbergMarquardt;
  internal::LevenbergMarquardtPolicy policy{options.initial_lambda, options.max_lambda, lm};
  Eigen::VectorXd g, diag;
  double cost = 0;
  Eigen::VectorXd delta;  // reused across iterations (8 MB at 10⁶ steps)
  // The LM candidate x ⊕ δ is formed in x itself, and a flat copy of x (n
  // doubles) puts it back if the step is rejected: a candidate copy of the
  // Values was 64 MB of fresh memory and a million small allocations at 10⁶
  // steps.
  Eigen::VectorXd x_before;
  internal::AndersonMixing anderson{options.anderson_memory};
  Eigen::VectorXd gauss_newton_step;  // the undamped step before the mix (anderson_memory > 0)
  bool factored_at_solution = false;  // the last step kept its factorization (relinearize_at_solution false)
  double factored_cost = 0;           // the cost where it was factored (g is that point's)
  internal::Retraction retraction;  // x ⊕ δ on rotation blocks (docs/DESIGN.md §12)

  Iteration(Impl& impl, const BatchSolverOptions& o, const FactorGraph& gr, Values& values, BatchSolverSummary& summary)
      : s(impl), options(o), graph(gr), x(values), sum(summary), retraction(internal::Retraction::of(gr, values)) {
    cost = s.linearize(graph, x, g, diag);
    sum.initial_cost = cost;
  }

  bool stepConverged(const Eigen::VectorXd& d, const Values& at) const {
    return d.norm() <= options.step_tolerance * (internal::norm(at) + options.step_tolerance);
  }
  // Stops with `reason` once the policy has finished undamped.
  bool converge(Termination reason) {
    if (!policy.converged()) return false;  // keep going, undamped
    sum.termination = reason;
    return true;
  }

  void run() {
    if (g.lpNorm<Eigen::Infinity>() <= options.gradient_tolerance) {
      sum.termination = Termination::GradientConverged;
      return;
    }
    for (;;) {
      if (sum.iterations >= options.max_iterations) {
        sum.termination = Termination::MaxIterations;
        return;
      }
      if (!dampedStep()) return;
    }
  }

  // Factors H + λD, solves for δ and tries it; false when the solve is done.
  bool dampedStep() {
    s.setDamping(diag, policy.lambda());
    ++sum.factorizations;
    const Eigen::Index bad = s.factorize();
    if (bad >= 0) {
      // Undamped (Gauss–Newton, or LM finishing after its tests passed) the
      // information matrix itself is singular: the final factorization would
      // fail the same way, and damping again only led back here, forever.
      if (policy.undamped() || !policy.canDampMore()) s.throwSingular(bad, diag);
      policy.singular();
      ++sum.rejected_steps;
      return true;
    }
    delta = -g;
    s.solveInPlace(delta);  // −H⁻¹g, exactly the negated solution
    const double predicted = -0.5 * g.dot(delta);  // the Gauss–Newton model's decrease
    if (!options.relinearize_at_solution && policy.undamped() && predicted <= options.relative_cost_tolerance * cost) {
      internal::flatten(x, s.factored_point);
      factored_cost = cost;
      internal::addStep(x, delta, x, &retraction);  // the last step: H as factored stays the solution's
      ++sum.iterations;
      cost -= predicted;
      factored_at_solution = true;
      sum.termination = Termination::CostConverged;
      return false;
    }
    if (stepConverged(delta, x) || (policy.lambda() == 0 && predicted <= options.decrease_tolerance)) {
      // λ already reached 0: the last steps were undamped, so there is no
      // damping bias to remove by one more, identical factorization
      if (policy.lambda() == 0 && !policy.undamped()) policy.converged();
      if (policy.undamped()) {  // a tiny undamped step is still the exact correction: take it
        internal::addStep(x, delta, x, &retraction);
        cost = s.linearize(graph, x, g, diag);
      }
      return !converge(Termination::StepConverged);
    }
    return tryStep(accelerate());
  }

  // An undamped step mixed with the last ones (anderson_memory; the tests
  // above judged Gauss–Newton's own); true when δ is a mix.
  bool accelerate() {
    if (options.anderson_memory == 0) return false;
    if (policy.lambda() != 0) {  // a damped step: no sequence of undamped ones to extrapolate
      anderson.reset();
      return false;
    }
    gauss_newton_step = delta;
    if (!anderson.mix(gauss_newton_step, diag, delta)) return false;
    if (g.dot(delta) < 0) return true;
    delta = gauss_newton_step;  // the mix is not downhill: Gauss–Newton's step, and a fresh history
    anderson.reset();
    return false;
  }

  // x ⊕ δ, kept if the policy accepts its cost (a mix, under any method:
  // as an undamped step, unless it raises the cost); false when the solve
  // is done.
  bool tryStep(bool mixed) {
    internal::flatten(x, x_before);
    internal::addStep(x, delta, x, &retraction);
    // Linearize at the candidate right away (its cost comes with it): one
    // pass over the factors per accepted step instead of two; a rejected
    // step refills H, g and the diagonal at the point it goes back to (so
    // no second gradient and diagonal are kept: 16 MB at 10⁶ steps).
    const double new_cost = s.linearize(graph, x, g, diag, true);
    if (mixed && !internal::LevenbergMarquardtPolicy::acceptUndamped(new_cost, cost)) {
      ++sum.anderson_rejected;
      anderson.reset();  // back, and Gauss–Newton's own step next
      internal::unflatten(x_before, x);
      cost = s.linearize(graph, x, g, diag);
      return true;
    }
    if (!std::isfinite(new_cost) && !lm)  // Gauss–Newton cannot back off: say which factor
      s.linearize(graph, x, g, diag);
    if (!policy.accept(new_cost, cost)) {
      ++sum.rejected_steps;
      anderson.reset();
      internal::unflatten(x_before, x);
      cost = s.linearize(graph, x, g, diag);
      // The damped solution was already converged; or λ had reached 0 and
      // the step moved the cost by rounding alone (after a mix that landed
      // on the minimum: more damping would only shrink a step to nothing)
      if (policy.undamped() ||
          (policy.lambda() == 0 && internal::LevenbergMarquardtPolicy::acceptUndamped(new_cost, cost))) {
        sum.termination = Termination::CostConverged;
        return false;
      }
      if (!policy.rejected()) {
        sum.termination = Termination::NoProgress;
        return false;
      }
      return true;
    }
    ++sum.iterations;
    if (mixed) ++sum.anderson_steps;
    anderson.accepted(delta);  // records a step only after a mix() (anderson_memory > 0)
    const double old_cost = cost;
    cost = new_cost;
    policy.accepted();
    if (g.lpNorm<Eigen::Infinity>() <= options.gradient_tolerance) return !converge(Termination::GradientConverged);
    if (old_cost - cost <= options.relative_cost_tolerance * old_cost) return !converge(Termination::CostConverged);
    return true;
  }

  // Up to newton_polish_steps full Newton steps (second-order terms included).
  void polish() {
    Values trial_x;
    const internal::NewtonPolishResult result = internal::newtonPolish(
        x, cost, options.newton_polish_steps,
        [&](internal::NewtonSystem& sys, const Values& at) {
          Eigen::VectorXd r;
          std::vector<Eigen::MatrixXd> J;
          for (const auto& f : graph) {
            f->linearizeRobust(at, r, &J);
            const Eigen::MatrixXd C = internal::residualCurvature(*f, at, r);
            sys.add(f->keys(), r, J, &C);
          }
        },
        [&](Values& next) {
          trial_x = next;
          return graph.cost(next);
        },
        [&](bool keep) {
          if (keep) x = std::move(trial_x);
        },
        [&](const Values&, const Values& next, const Eigen::VectorXd& d) { return stepConverged(d, next); });
    sum.newton_steps = result.steps;
    cost = result.cost;
    if (sum.newton_steps > 0) cost = s.linearize(graph, x, g, diag);  // JᵀJ at the solution
  }

  // Factors the undamped information matrix at the solution: it gives the
  // marginal covariances and tells whether the solution is determined.
  void factorAtSolution() {
    s.setDamping(diag, 0.0);
    ++sum.factorizations;
    const Eigen::Index bad = s.factorize();
    if (bad >= 0) s.throwSingular(bad, diag);
  }
};

BatchSolverSummary BatchSolver::solve(const FactorGraph& graph, Values& values) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  Impl& s = *impl_;
  s.setup(graph, values, options_.threads);

  BatchSolverSummary sum;
  sum.num_factors = graph.size();
  sum.num_variables = values.size();
  sum.dimension = s.n;
  sum.linear_solver = s.linearSolver();

  // The iterate lives in `values` itself (a copy of a million-step run is
  // 64 MB of fresh memory and a million small allocations); a flat copy of
  // the start puts it back if the solve throws (strong guarantee).
  Eigen::VectorXd start_flat;
  internal::flatten(values, start_flat);
  struct RestoreOnThrow {
    Values& v;
    const Eigen::VectorXd& flat;
    bool armed = true;
    ~RestoreOnThrow() {
      if (armed) internal::unflatten(flat, v);  // same keys and sizes: no allocation
    }
  } restore{values, start_flat};
  Impl::Iteration it(s, options_, graph, values, sum);
  it.run();
  // The polish's curvature differences are taken in +: not on rotation blocks.
  if (isConverged(sum.termination) && options_.newton_polish_steps > 0 && it.retraction.trivial()) it.polish();
  if (!it.factored_at_solution) {
    it.factorAtSolution();
    internal::flatten(values, s.factored_point);
    it.factored_cost = it.cost;
  }
  if (options_.covariance_by_qr && s.use_envelope) {  // at the point H was factored at
    if (!it.factored_at_solution) {
      s.factorByRows(graph, values, it.diag);
    } else {  // the last step taken without a linearization after it
      Values at = values;
      internal::unflatten(s.factored_point, at);
      s.factorByRows(graph, at, it.diag);
    }
    ++sum.factorizations;
  }
  s.has_solution = true;
  restore.armed = false;

  sum.final_cost = it.cost;
  sum.gradient_norm = it.g.lpNorm<Eigen::Infinity>();
  // What stepAfterChange() starts from, moved (no copy of n doubles a solve).
  s.factored_gradient = std::move(it.g);
  s.factored_cost = it.factored_cost;
  s.retraction = std::move(it.retraction);
  sum.converged = isConverged(sum.termination);
  sum.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  sum.message = toString(sum.termination);
  return sum;
}

void BatchSolver::evaluateAt(const FactorGraph& graph, const Values& values) {
  Impl& s = *impl_;
  s.setup(graph, values, options_.threads);
  Eigen::VectorXd g, diag;
  const double cost = s.linearize(graph, values, g, diag);
  s.setDamping(diag, 0.0);
  const Eigen::Index bad = s.factorize();
  if (bad >= 0) s.throwSingular(bad, diag);
  s.has_solution = true;
  internal::flatten(values, s.factored_point);
  s.factored_gradient = std::move(g);
  s.factored_cost = cost;
  s.retraction = internal::Retraction::of(graph, values);
}

Values BatchSolver::factoredAt(const Values& like) const {
  const Impl& s = *impl_;
  if (!s.has_solution) throw InvalidArgument("BatchSolver: no solution yet; call solve() before factoredAt()");
  if (like.dim() != s.factored_point.size())
    throw InvalidArgument("BatchSolver::factoredAt: the values have " + std::to_string(like.dim()) +
                          " entries, the last solve " + std::to_string(s.factored_point.size()));
  Values out = like;
  internal::unflatten(s.factored_point, out);
  return out;
}

ChangeStep BatchSolver::stepAfterChange(const GraphChange& change, Values& values) {
  Impl& s = *impl_;
  if (!s.has_solution)
    throw InvalidArgument("BatchSolver::stepAfterChange: no factorization of the graph before the change; solve() it first");
  if (values.dim() != s.factored_point.size())
    throw InvalidArgument("BatchSolver::stepAfterChange: the values have " + std::to_string(values.dim()) +
                          " entries, the last solve " + std::to_string(s.factored_point.size()));
  // x_f in `values` itself (no copy of every vector); put back on a throw.
  internal::flatten(values, s.change_backup);
  internal::unflatten(s.factored_point, values);
  try {
    internal::LocalChange& c = s.change;
    internal::linearizeChange(change, values, c);
    internal::LowRankCorrection& e = s.correction;
    internal::lowRankCorrection(c, e);
    ChangeStep out;
    out.rank = e.E.rows();
    out.cost_before = s.factored_cost - c.cost_removed + c.cost_added;
    const Eigen::VectorXd delta = s.changedStep(c, e, out.predicted_decrease);
    internal::addStep(values, delta, values, &s.retraction);
    for (const Key& k : change.dropped) values.erase(k);
    s.has_solution = false;  // H's factor is the old graph's
    return out;
  } catch (...) {
    internal::unflatten(s.change_backup, values);
    throw;
  }
}

Eigen::MatrixXd BatchSolver::jointMarginalCovariance(const std::vector<Key>& keys) const {
  Impl& s = *impl_;
  if (!s.has_solution)
    throw InvalidArgument("BatchSolver: no solution yet; call solve() before asking for covariances");
  // Each key's first column (offs) and size (dims), in one buffer: a run
  // asks this once per step.
  std::vector<Eigen::Index> columns(2 * keys.size());
  Eigen::Index* offs = columns.data();
  Eigen::Index* dims = offs + keys.size();
  Eigen::Index m = 0;
  for (std::size_t a = 0; a < keys.size(); ++a) {
    const std::size_t i = s.positionOf(keys[a]);
    if (i == Impl::npos)
      throw InvalidArgument("BatchSolver: " + keys[a].toString() + " is not a variable of the last solve");
    offs[a] = s.offset[i];
    dims[a] = s.offset[i + 1] - s.offset[i];
    m += dims[a];
  }
  // One small variable the envelope's selected inverse has not reached (a
  // window's oldest states): a forward substitution per column beats the
  // sweep up to it — once per factorization, so that asking for every
  // state in turn still takes one sweep, not one substitution each.
  if (s.use_envelope && keys.size() == 1 && !s.envelope_block_used && offs[0] < s.envelope.inverseFrom() &&
      s.envelope.inverseBlockWork(offs[0], dims[0]) < s.envelope.sweepWork(offs[0])) {
    s.envelope_block_used = true;
    return s.envelope.inverseBlock(offs[0], dims[0]);
  }
  Eigen::MatrixXd out(m, m);
  // Fast path: every requested entry lies on the factor's pattern (true for
  // any x_c(k) with x_b), so it is read from the selected inverse; the lower
  // triangle mirrors the upper.
  bool on_pattern = true;
  for (std::size_t a = 0, r = 0; a < keys.size() && on_pattern; r += dims[a], ++a)
    for (std::size_t b = a, c = r; b < keys.size() && on_pattern; c += dims[b], ++b)
      for (Eigen::Index i = 0; i < dims[a] && on_pattern; ++i)
        for (Eigen::Index j = b == a ? i : 0; j < dims[b] && on_pattern; ++j) {
          on_pattern = s.inverseEntry(offs[a] + i, offs[b] + j, out(r + i, c + j));
          if (on_pattern) out(c + j, r + i) = out(r + i, c + j);
        }
  if (on_pattern) return out;
  // Otherwise: the needed columns of H⁻¹ by solving H X = E.
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(s.n, m);
  Eigen::Index c = 0;
  for (std::size_t i = 0; i < keys.size(); ++i)
    for (Eigen::Index j = 0; j < dims[i]; ++j) E(offs[i] + j, c++) = 1.0;
  const Eigen::MatrixXd X = s.solve(E);
  Eigen::Index r = 0;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    out.middleRows(r, dims[i]) = X.middleRows(offs[i], dims[i]);
    r += dims[i];
  }
  return 0.5 * (out + out.transpose());
}

Eigen::MatrixXd BatchSolver::marginalCovariance(const Key& key) const {
  return jointMarginalCovariance({key});
}

}  // namespace gssm
