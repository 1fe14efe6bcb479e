// The internal factorization: the dense path (≤ kDenseMax unknowns) and the
// CHOLMOD path give the solution, the selected inverse and the failing
// column of a dense Eigen reference.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "linear/sparse_cholesky.h"

using gssm::internal::SparseCholesky;

namespace {
// The upper-triangle entries of H in the order fill() adds them: column by
// column, rows ascending in the band and descending in the border (so the
// long border columns arrive unsorted, as the constants' do from a graph).
template <class F>
void forEachUpper(const Eigen::MatrixXd& H, F&& f) {
  const Eigen::Index n = H.rows();
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index k = 0; k <= j; ++k) {
      const Eigen::Index i = j >= n - 2 ? j - k : k;
      if (H(i, j) != 0) f(i, j);
    }
}

// A banded SPD matrix with a dense border (the GSSM's shape), given to the
// factorization as upper-triangle triplets with every entry split in two
// (duplicates must be summed). A wide band makes CHOLMOD go supernodal.
Eigen::MatrixXd fill(SparseCholesky& c, Eigen::Index n, unsigned seed, Eigen::Index indefinite_at = -1,
                     Eigen::Index band = 2) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i <= j; ++i)
      if (j - i <= band || j >= n - 2) H(i, j) = H(j, i) = (i == j ? 8.0 * std::max<Eigen::Index>(1, band / 2) : u(rng));
  if (indefinite_at >= 0) H(indefinite_at, indefinite_at) = -1.0;
  std::size_t nnz = 0;
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i <= j; ++i) nnz += H(i, j) != 0 ? 2 : 0;
  c.reset(n, nnz);
  forEachUpper(H, [&](Eigen::Index i, Eigen::Index j) {
    c.add(i, j, 0.25 * H(i, j));
    c.add(i, j, 0.75 * H(i, j));
  });
  return H;
}
}  // namespace

TEST(SparseCholesky, DenseAndSparsePathsEqualADenseReference) {
  // Dense, simplicial (band 2) and supernodal (band 24: ≥ 16 entries per column of L).
  const std::pair<Eigen::Index, Eigen::Index> cases[] = {
      {12, 2}, {SparseCholesky::kDenseMax, 2}, {SparseCholesky::kDenseMax + 1, 2}, {150, 2}, {150, 24}};
  for (const auto& [n, band] : cases) {
    SparseCholesky c;
    const Eigen::MatrixXd H = fill(c, n, 3 + static_cast<unsigned>(n + band), -1, band);
    ASSERT_EQ(c.factorize(), -1) << n;
    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 3);
    const Eigen::MatrixXd X = c.solve(B);
    EXPECT_LT((H * X - B).norm() / B.norm(), 1e-12) << n;
    const Eigen::MatrixXd Hinv = H.inverse();
    const auto S = c.selectedInverse();
    for (Eigen::Index j = 0; j < n; ++j)
      for (Eigen::Index i = j; i < n; ++i) {
        double v;
        if (S.lookup(i, j, v)) {
          EXPECT_NEAR(v, Hinv(i, j), 1e-12) << n << " (" << i << ", " << j << ")";
        }
        if (i == j || i - j <= band || i >= n - 2) {
          EXPECT_TRUE(S.lookup(i, j, v)) << "pattern entry missing";
        }
      }
    // Values overwritten in place through the entries' slots (each entry
    // was added as two parts, in fill()'s order): H doubled, same pattern.
    std::fill(c.values(), c.values() + c.nonzeros(), 0.0);
    std::size_t e = 0;
    forEachUpper(H, [&](Eigen::Index i, Eigen::Index j) {
      c.values()[c.slot(e++)] += 0.5 * H(i, j);
      c.values()[c.slot(e++)] += 1.5 * H(i, j);
    });
    ASSERT_EQ(e, c.entries());
    ASSERT_EQ(c.factorize(), -1);
    EXPECT_LT((2 * H * c.solve(B) - B).norm() / B.norm(), 1e-12) << n;
  }
}

TEST(SparseCholesky, BothPathsReportTheColumnThatIsNotPositiveDefinite) {
  for (const Eigen::Index n : {Eigen::Index(30), Eigen::Index(120)}) {
    SparseCholesky c;
    fill(c, n, 9, n / 3);
    EXPECT_EQ(c.factorize(), n / 3) << n;
  }
}
