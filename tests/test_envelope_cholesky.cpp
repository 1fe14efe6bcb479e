// The envelope Cholesky against a dense one (Eigen's LLᵀ and inverse) on
// random SPD matrices of the batch solver's shapes — a chain of states with
// a constants' border, scalar and 3-wide states, wider bands — and on a
// general profile: the solution, H⁻¹ on the whole envelope, the first
// column that is not positive definite.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <random>

#include "gssm/core/error.h"
#include "linear/envelope_cholesky.h"

using gssm::internal::EnvelopeCholesky;

namespace {
// A random SPD matrix with the pattern of a chain of `steps` states of size
// nc (each coupled to the next) and nb constants coupled to all, plus the
// first row of each column's envelope (and J, H = JᵀJ, with its rows).
Eigen::MatrixXd chainMatrix(std::mt19937& rng, int steps, int nc, int nb, std::vector<int>& first,
                            Eigen::MatrixXd* J_out = nullptr) {
  std::normal_distribution<double> g;
  const int n = steps * nc + nb;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3 * n, n);
  int row = 0;
  for (int k = 0; k < steps; ++k)  // a factor on (x_k, x_{k+1}, x_b) per step, and one on (x_k, x_b)
    for (int r = 0; r < nc; ++r, ++row) {
      for (int c = k * nc; c < std::min((k + 2) * nc, steps * nc); ++c) J(row, c) = g(rng);
      for (int c = steps * nc; c < n; ++c) J(row, c) = g(rng);
      ++row;
      for (int c = k * nc; c < (k + 1) * nc; ++c) J(row, c) = g(rng);
      for (int c = steps * nc; c < n; ++c) J(row, c) = 0.5 * g(rng);
    }
  for (int c = 0; c < n; ++c, ++row) J(row % J.rows(), c) += 1.0;  // every column reached
  const Eigen::MatrixXd H = J.transpose() * J + 1e-3 * Eigen::MatrixXd::Identity(n, n);
  if (J_out) {
    *J_out = Eigen::MatrixXd(J.rows() + n, n);
    *J_out << J, std::sqrt(1e-3) * Eigen::MatrixXd::Identity(n, n);
  }
  first.assign(static_cast<std::size_t>(n), 0);
  for (int j = 0; j < n; ++j) {
    int f = j;
    for (int i = 0; i < j; ++i)
      if (H(i, j) != 0) {
        f = i;
        break;
      }
    first[static_cast<std::size_t>(j)] = f;
  }
  return H;
}

void fill(EnvelopeCholesky& c, const Eigen::MatrixXd& H, const std::vector<int>& first) {
  c.setPattern(first);
  for (Eigen::Index j = 0; j < H.cols(); ++j)
    for (Eigen::Index i = first[static_cast<std::size_t>(j)]; i <= j; ++i) c.values()[c.position(i, j)] = H(i, j);
}

// Factors H = JᵀJ from J's rows, in order (addRow), their zeros left out.
Eigen::Index factorByRows(EnvelopeCholesky& c, const Eigen::MatrixXd& J) {
  c.beginRows();
  std::vector<int> cols;
  std::vector<double> vals;
  for (Eigen::Index r = 0; r < J.rows(); ++r) {
    cols.clear(), vals.clear();
    for (Eigen::Index j = 0; j < J.cols(); ++j)
      if (J(r, j) != 0) cols.push_back(static_cast<int>(j)), vals.push_back(J(r, j));
    c.addRow(cols.data(), vals.data(), static_cast<int>(cols.size()));
  }
  return c.finishRows();
}

// With J: factored from its rows (a QR), not from H.
void expectMatchesDense(const Eigen::MatrixXd& H, const std::vector<int>& first, std::mt19937& rng,
                        const Eigen::MatrixXd* J = nullptr) {
  EnvelopeCholesky c;
  fill(c, H, first);
  ASSERT_EQ(J ? factorByRows(c, *J) : c.factorize(), -1);
  std::normal_distribution<double> g;
  Eigen::VectorXd b(H.rows());
  for (Eigen::Index i = 0; i < b.size(); ++i) b[i] = g(rng);
  const Eigen::VectorXd x_dense = H.llt().solve(b);
  Eigen::VectorXd x = b;
  c.solveInPlace(x);
  EXPECT_LT((x - x_dense).norm(), 1e-9 * (1 + x_dense.norm()));
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(H.rows(), 3);
  EXPECT_LT((c.solve(B) - H.llt().solve(B)).norm(), 1e-9 * (1 + B.norm()));
  // A block by forward substitution, anywhere: the top (a window's oldest
  // state), the middle, the last column.
  const Eigen::MatrixXd Hinv = H.inverse();
  const Eigen::Index n = H.rows();
  for (auto [first_col, size] : {std::pair<Eigen::Index, Eigen::Index>{0, std::min<Eigen::Index>(3, n)}, {n / 3, 1}, {n - 1, 1}})
    EXPECT_LT((c.inverseBlock(first_col, size) - Hinv.block(first_col, first_col, size, size)).norm(),
              1e-9 * (1 + Hinv.block(first_col, first_col, size, size).norm()))
        << "block " << first_col << " + " << size;
  // The sweep in two parts: the lower half's rows first (what a window's
  // newest state and constants need), then resumed to the top.
  for (const Eigen::Index from : {H.rows() / 2, Eigen::Index{0}}) {
    c.selectedInverse(from);
    EXPECT_EQ(c.inverseFrom(), from);
    double worst = 0;
    for (Eigen::Index j = 0; j < H.cols(); ++j)
      for (Eigen::Index i = 0; i < H.rows(); ++i) {
        double z = 0;
        const bool in = c.inverseEntry(i, j, z);
        const bool held = std::min(i, j) >= first[static_cast<std::size_t>(std::max(i, j))] && std::min(i, j) >= from;
        EXPECT_EQ(in, held) << i << ", " << j << " (sweep down to row " << from << ")";
        if (in) worst = std::max(worst, std::abs(z - Hinv(i, j)) / std::max(1.0, std::abs(Hinv(i, j))));
      }
    EXPECT_LT(worst, 1e-9) << "sweep down to row " << from;
  }
}
}  // namespace

TEST(EnvelopeCholesky, ChainsWithAConstantsBorderMatchTheDenseFactorization) {
  std::mt19937 rng(2);
  // {60, 6, 25}: the UWB layout, whose constants' panel takes the Gram
  // matrix of its rows above (and {10, 4, 5}: too few rows for that).
  for (auto [steps, nc, nb] : {std::tuple{1, 1, 0}, {50, 1, 2}, {40, 3, 2}, {30, 2, 0}, {25, 1, 6}, {10, 4, 5}, {60, 6, 25}}) {
    std::vector<int> first;
    const Eigen::MatrixXd H = chainMatrix(rng, steps, nc, nb, first);
    SCOPED_TRACE(::testing::Message() << steps << " steps, nc " << nc << ", nb " << nb);
    expectMatchesDense(H, first, rng);
  }
}

// The factor from J's rows (a Givens QR, R = U) gives the same solves,
// blocks and selected inverse; rows in any order give the same factor.
TEST(EnvelopeCholesky, FactorFromTheJacobiansRowsMatchesTheDenseFactorization) {
  std::mt19937 rng(4);
  for (auto [steps, nc, nb] : {std::tuple{1, 1, 0}, {50, 1, 2}, {40, 3, 2}, {30, 2, 0}, {10, 4, 5}, {60, 6, 25}}) {
    std::vector<int> first;
    Eigen::MatrixXd J;
    const Eigen::MatrixXd H = chainMatrix(rng, steps, nc, nb, first, &J);
    SCOPED_TRACE(::testing::Message() << steps << " steps, nc " << nc << ", nb " << nb);
    expectMatchesDense(H, first, rng, &J);
    EnvelopeCholesky in_order, reversed;
    fill(in_order, H, first);
    fill(reversed, H, first);
    ASSERT_EQ(factorByRows(in_order, J), -1);
    ASSERT_EQ(factorByRows(reversed, J.colwise().reverse()), -1);
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(H.rows(), 2);
    EXPECT_LT((in_order.solve(B) - reversed.solve(B)).norm(), 1e-9 * (1 + in_order.solve(B).norm()));
  }
  // A column no row reaches has no pivot: named.
  std::vector<int> first;
  Eigen::MatrixXd J;
  const Eigen::MatrixXd H = chainMatrix(rng, 10, 2, 1, first, &J);
  J.col(7).setZero();
  EnvelopeCholesky c;
  fill(c, H, first);
  EXPECT_EQ(factorByRows(c, J), 7);
}

TEST(EnvelopeCholesky, AGeneralProfileMatchesTheDenseFactorization) {
  // Random first rows (the envelope a loop closure would make), zeros inside.
  std::mt19937 rng(3);
  const int n = 60;
  std::uniform_int_distribution<int> u(0, 100);
  std::normal_distribution<double> g;
  std::vector<int> first(n);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    first[static_cast<std::size_t>(j)] = u(rng) < 20 ? u(rng) * j / 100 : std::max(0, j - 2);
    for (int i = first[static_cast<std::size_t>(j)]; i < j; ++i)
      if (i == first[static_cast<std::size_t>(j)] || u(rng) < 40) A(i, j) = A(j, i) = g(rng);
  }
  for (int j = 0; j < n; ++j) A(j, j) = 1 + A.col(j).cwiseAbs().sum();  // diagonally dominant: SPD
  expectMatchesDense(A, first, rng);
}

TEST(EnvelopeCholesky, ReportsTheFirstColumnThatIsNotPositiveDefinite) {
  std::mt19937 rng(4);
  std::vector<int> first;
  Eigen::MatrixXd H = chainMatrix(rng, 20, 1, 2, first);
  // Make column 7 dependent on the earlier ones: H(7,7) = its Schur complement's 0.
  EnvelopeCholesky c;
  fill(c, H, first);
  ASSERT_EQ(c.factorize(), -1);
  const Eigen::Index bad = 7;
  const Eigen::MatrixXd Hs = H.topLeftCorner(bad, bad);
  const Eigen::VectorXd h = H.col(bad).head(bad);
  H(bad, bad) = h.dot(Hs.llt().solve(h)) - 1e-9;  // just below: not positive definite
  fill(c, H, first);
  EXPECT_EQ(c.factorize(), bad);
  H(bad, bad) = std::nan("");
  fill(c, H, first);
  EXPECT_EQ(c.factorize(), bad);
  Eigen::VectorXd b = Eigen::VectorXd::Ones(H.rows());
  EXPECT_THROW(c.solveInPlace(b), gssm::NumericalError);
}

TEST(EnvelopeCholesky, ReportsTheFirstConstantThatIsNotPositiveDefiniteInAWidePanel) {
  // 12 constants over 40 states' rows: the panel factored through the Gram
  // matrix of its rows above; constant 5 made dependent on the columns before.
  std::mt19937 rng(5);
  std::vector<int> first;
  Eigen::MatrixXd H = chainMatrix(rng, 40, 2, 12, first);
  const Eigen::Index bad = 80 + 5;
  const Eigen::MatrixXd Hs = H.topLeftCorner(bad, bad);
  const Eigen::VectorXd h = H.col(bad).head(bad);
  H(bad, bad) = h.dot(Hs.llt().solve(h)) - 1e-9;
  EnvelopeCholesky c;
  fill(c, H, first);
  EXPECT_EQ(c.factorize(), bad);
  H(bad, bad) = std::nan("");
  fill(c, H, first);
  EXPECT_EQ(c.factorize(), bad);
}

// Eigen's product blocking follows the cache sizes it is given, and the
// blocking orders a large product's sums: the library fixes them when it
// loads, so that no estimate depends on the CPU's caches (src/linear/
// product_blocking.cpp; this machine's own, read by CPUID, differ on most).
TEST(ProductBlocking, EigensCacheSizesArePinnedWhenTheLibraryLoads) {
  EXPECT_EQ(Eigen::l1CacheSize(), 48 * 1024);
  EXPECT_EQ(Eigen::l2CacheSize(), 1024 * 1024);
  EXPECT_EQ(Eigen::l3CacheSize(), 32 * 1024 * 1024);
}
