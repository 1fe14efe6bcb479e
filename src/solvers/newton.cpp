#include "solvers/newton.h"

#include <cmath>
#include <unordered_map>

#include "gssm/core/rotation_blocks.h"

#include "linear/normal_equations.h"

namespace gssm::internal {

Eigen::MatrixXd residualCurvature(const Factor& f, const Values& x, const Eigen::VectorXd& r) {
  const auto& keys = f.keys();
  std::vector<Eigen::Index> off(keys.size() + 1, 0);
  for (std::size_t a = 0; a < keys.size(); ++a) off[a + 1] = off[a] + x.at(keys[a]).size();
  const Eigen::Index n = off.back();
  Eigen::MatrixXd C(n, n);
  Values xp;  // the factor's keys only: x may hold a whole run
  for (const auto& k : keys) xp.insert(k, x.at(k));
  Eigen::VectorXd rp;
  std::vector<Eigen::MatrixXd> Jp, Jm;
  auto JTr = [&](const std::vector<Eigen::MatrixXd>& J) {
    Eigen::VectorXd out(n);
    for (std::size_t a = 0; a < keys.size(); ++a) out.segment(off[a], off[a + 1] - off[a]) = J[a].transpose() * r;
    return out;
  };
  for (std::size_t a = 0; a < keys.size(); ++a) {
    Eigen::VectorXd& v = xp.at(keys[a]);
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      const double v0 = v[i];
      const double h = 1e-5 * std::max(1.0, std::abs(v0));  // ~ε^(1/3): central-difference optimum
      v[i] = v0 + h;
      f.linearize(xp, rp, &Jp);
      v[i] = v0 - h;
      f.linearize(xp, rp, &Jm);
      v[i] = v0;
      C.col(off[a] + i) = (JTr(Jp) - JTr(Jm)) / (2 * h);
    }
  }
  return 0.5 * (C + C.transpose());
}

NewtonSystem::NewtonSystem(const Values& layout) : layout_(layout) {
  Eigen::Index n = 0;
  for (const auto& kv : layout) {
    offset_.push_back(n);
    n += kv.second.size();
  }
  offset_.push_back(n);
  g_ = Eigen::VectorXd::Zero(n);
  chol_.reset(n, static_cast<std::size_t>(4 * n + 16));
}

void NewtonSystem::add(const std::vector<Key>& keys, const Eigen::VectorXd& r,
                       const std::vector<Eigen::MatrixXd>& J, const Eigen::MatrixXd* curvature) {
  std::vector<Eigen::Index> offs(keys.size());
  for (std::size_t a = 0; a < keys.size(); ++a) {
    offs[a] = offset_[layout_.indexOf(keys[a])];
    g_.segment(offs[a], J[a].cols()) += J[a].transpose() * r;
  }
  FactorColumns columns;
  columns.gather(offs.data(), J);
  // The curvature is over the factor's stacked variables: column p's row and column.
  forEachUpperJtJ(columns, [&](Eigen::Index gi, Eigen::Index gj, double v, std::size_t p, std::size_t q) {
    if (curvature) v += (*curvature)(static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(q));
    chol_.add(gi, gj, v);  // duplicates are summed
  });
}

bool NewtonSystem::solve(Eigen::VectorXd& delta) {
  if (chol_.factorize() >= 0) return false;
  delta = -chol_.solve(g_);
  return delta.allFinite();
}

Retraction Retraction::of(const FactorGraph& graph, const Values& x) {
  std::unordered_map<Key, Factor::Rotations, KeyHash> found;
  for (const auto& f : graph)
    for (std::size_t a = 0; a < f->keys().size(); ++a) {
      const Factor::Rotations r = f->rotationsOf(a);
      if (r.blocks && x.contains(f->keys()[a]) && hasRotationIn(*r.blocks, x.at(f->keys()[a]).size(), r.offset))
        found.emplace(f->keys()[a], r);
    }
  Retraction out;
  if (found.empty()) return out;
  for (const auto& kv : x) {
    const auto it = found.find(kv.first);
    out.by_position.push_back(it == found.end() ? Factor::Rotations{} : it->second);
  }
  return out;
}

Values addStep(const Values& x, const Eigen::VectorXd& delta, const Retraction* retraction) {
  Values out = x;
  addStep(x, delta, out, retraction);
  return out;
}

void addStep(const Values& x, const Eigen::VectorXd& delta, Values& out, const Retraction* retraction) {
  const bool plain = !retraction || retraction->trivial();
  auto it = out.begin();
  Eigen::Index off = 0;
  std::size_t i = 0;
  for (const auto& kv : x) {
    const Factor::Rotations* r = plain ? nullptr : &retraction->by_position[i++];
    if (r && r->blocks) {
      it->second = kv.second;
      retractBlocks(it->second, delta.segment(off, kv.second.size()), *r->blocks, r->offset);
    } else {
      it->second = kv.second + delta.segment(off, kv.second.size());
    }
    off += kv.second.size();
    ++it;
  }
}

void flatten(const Values& x, Eigen::VectorXd& flat) {
  flat.resize(x.dim());
  Eigen::Index off = 0;
  for (const auto& kv : x) {
    flat.segment(off, kv.second.size()) = kv.second;
    off += kv.second.size();
  }
}

void unflatten(const Eigen::VectorXd& flat, Values& x) {
  Eigen::Index off = 0;
  for (auto& kv : x) {
    kv.second = flat.segment(off, kv.second.size());
    off += kv.second.size();
  }
}

double norm(const Values& x) {
  double sq = 0;
  for (const auto& kv : x) sq += kv.second.squaredNorm();
  return std::sqrt(sq);
}

}  // namespace gssm::internal
