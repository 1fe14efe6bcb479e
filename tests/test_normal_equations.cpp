// The scatter of a factor's JᵀJ into the upper triangle of H (batch solver,
// Newton system) against a dense JᵀJ: keys in order, out of order, and a
// variable listed twice.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "linear/normal_equations.h"

using gssm::internal::FactorColumns;

namespace {
// H (n × n, upper triangle) from the factor's blocks J[a] at columns offs[a].
Eigen::MatrixXd scattered(const std::vector<Eigen::Index>& offs, const std::vector<Eigen::MatrixXd>& J, Eigen::Index n) {
  FactorColumns columns;
  columns.gather(offs.data(), J);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  std::size_t emitted = 0;
  gssm::internal::forEachUpperJtJ(columns, [&](Eigen::Index i, Eigen::Index j, double v, auto...) {
    EXPECT_LE(i, j);
    H(i, j) += v;
    ++emitted;
  });
  // The same enumeration from the layout alone (what the batch solver's
  // pattern is built from) visits the same number of entries.
  std::vector<Eigen::Index> dims;
  for (const auto& b : J) dims.push_back(b.cols());
  FactorColumns layout;
  layout.place(offs.data(), offs.size(), [&](std::size_t a) { return dims[a]; });
  std::size_t placed = 0;
  gssm::internal::forEachUpperPair(layout, [&](std::size_t, std::size_t) { ++placed; });
  EXPECT_EQ(placed, emitted);
  return H;
}

// The dense reference: J as one matrix over all n columns (a repeated
// variable's blocks add up), then the upper triangle of JᵀJ.
Eigen::MatrixXd reference(const std::vector<Eigen::Index>& offs, const std::vector<Eigen::MatrixXd>& J, Eigen::Index n) {
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(J[0].rows(), n);
  for (std::size_t a = 0; a < J.size(); ++a) full.middleCols(offs[a], J[a].cols()) += J[a];
  return Eigen::MatrixXd((full.transpose() * full).triangularView<Eigen::Upper>());
}
}  // namespace

TEST(NormalEquations, FactorJtJScatterEqualsADenseProduct) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0, 1);
  auto random = [&](Eigen::Index r, Eigen::Index c) {
    Eigen::MatrixXd m(r, c);
    for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = g(rng);
    return m;
  };
  const Eigen::Index n = 12;
  struct Case {
    std::vector<Eigen::Index> offs, dims;
    Eigen::Index rows;
  };
  const Case cases[] = {
      {{0, 2, 9}, {2, 3, 2}, 1},   // keys in order, a scalar residual
      {{0, 2, 9}, {2, 3, 2}, 3},   // in order, three rows
      {{9, 0, 4}, {2, 3, 1}, 2},   // out of order
      {{4, 9, 4}, {2, 1, 2}, 2},   // a variable listed twice
      {{4, 4}, {1, 1}, 2},         // ... twice in a row (its columns do not decrease)
  };
  for (const auto& c : cases) {
    std::vector<Eigen::MatrixXd> J;
    for (Eigen::Index d : c.dims) J.push_back(random(c.rows, d));
    const Eigen::MatrixXd H = scattered(c.offs, J, n), R = reference(c.offs, J, n);
    EXPECT_LT((H - R).cwiseAbs().maxCoeff(), 1e-12) << "first offsets " << c.offs[0] << ", " << c.offs[1] << "\n"
                                                     << H << "\n\n" << R;
  }
}
