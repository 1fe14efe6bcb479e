#include "solvers/change_step.h"

#include <algorithm>
#include <sstream>

#include "gssm/core/error.h"

namespace gssm::internal {

namespace {
void addKey(LocalChange& c, const Key& k, Eigen::Index dim) {
  if (std::find(c.keys.begin(), c.keys.end(), k) != c.keys.end()) return;
  c.keys.push_back(k);
  c.offset.push_back(c.offset.back() + dim);
}

// One factor's JᵀJ and Jᵀr into H, g on the local columns; its cost (r, J:
// the caller's buffers, reused from factor to factor).
double accumulate(LocalChange& c, const Factor& f, const Values& x_f, Eigen::MatrixXd& H, Eigen::VectorXd& g) {
  Eigen::VectorXd& r = c.r;
  std::vector<Eigen::MatrixXd>& J = c.J;
  const double cost = f.linearizeRobust(x_f, r, &J);
  if (!r.allFinite())
    throw NumericalError("BatchSolver::stepAfterChange: factor '" + f.describe() +
                         "' has a non-finite residual at the factored point");
  const auto col = [&](std::size_t a) {
    return c.offset[static_cast<std::size_t>(std::find(c.keys.begin(), c.keys.end(), f.keys()[a]) - c.keys.begin())];
  };
  for (std::size_t a = 0; a < f.keys().size(); ++a) {
    const Eigen::Index ca = col(a);
    g.segment(ca, J[a].cols()).noalias() += J[a].transpose() * r;
    for (std::size_t b = 0; b < f.keys().size(); ++b)
      H.block(ca, col(b), J[a].cols(), J[b].cols()).noalias() += J[a].transpose() * J[b];
  }
  return cost;
}
}  // namespace

bool clearlyPositiveDefinite(const Eigen::LLT<Eigen::MatrixXd>& llt, const Eigen::MatrixXd& A) {
  if (llt.info() != Eigen::Success) return false;
  return A.size() == 0 || llt.matrixLLT().diagonal().cwiseAbs2().minCoeff() > 1e-14 * A.diagonal().cwiseAbs().maxCoeff();
}

void linearizeChange(const GraphChange& change, const Values& x_f, LocalChange& c) {
  c.keys.clear();
  c.offset.assign(1, 0);
  c.cost_removed = c.cost_added = 0;
  const auto dimOf = [&](const Key& k) {
    if (!x_f.contains(k))
      throw InvalidArgument("BatchSolver::stepAfterChange: " + k.toString() + " is not a variable of the last solve");
    return static_cast<Eigen::Index>(x_f.at(k).size());
  };
  for (const Key& k : change.dropped) addKey(c, k, dimOf(k));
  c.dropped = c.keys.size();
  for (const auto& f : change.added)
    for (const Key& k : f->keys())
      if (std::find(change.dropped.begin(), change.dropped.end(), k) != change.dropped.end())
        throw InvalidArgument("BatchSolver::stepAfterChange: the added factor '" + f->describe() +
                              "' uses the dropped variable " + k.toString());
  for (const FactorGraph* g : {&change.removed, &change.added})
    for (const auto& f : *g)
      for (const Key& k : f->keys()) addKey(c, k, dimOf(k));
  const Eigen::Index m = c.columns();
  c.H_removed.setZero(m, m);
  c.H_added.setZero(m, m);
  c.g_removed.setZero(m);
  c.g_added.setZero(m);
  for (const auto& f : change.removed) c.cost_removed += accumulate(c, *f, x_f, c.H_removed, c.g_removed);
  for (const auto& f : change.added) c.cost_added += accumulate(c, *f, x_f, c.H_added, c.g_added);
}

void lowRankCorrection(const LocalChange& c, LowRankCorrection& out) {
  const Eigen::Index o = c.droppedColumns(), t = c.columns() - o;
  out.E = c.H_added.bottomRightCorner(t, t) - c.H_removed.bottomRightCorner(t, t);
  out.gradient_change = c.g_added.tail(t) - c.g_removed.tail(t);
  if (o == 0) return;
  const Eigen::MatrixXd OO = c.H_removed.topLeftCorner(o, o);
  const Eigen::LLT<Eigen::MatrixXd> oo(OO);
  if (!clearlyPositiveDefinite(oo, OO)) {
    std::ostringstream os;
    os << "BatchSolver::stepAfterChange: the removed factors do not determine the dropped variables (";
    for (std::size_t i = 0; i < c.dropped; ++i) os << (i ? ", " : "") << c.keys[i].toString();
    os << "): every factor on a dropped variable must be removed with it, and they must fix it (a prior)";
    throw NumericalError(os.str());
  }
  const auto OT = c.H_removed.topRightCorner(o, t);
  out.E.noalias() += OT.transpose() * oo.solve(OT);
}

}  // namespace gssm::internal
