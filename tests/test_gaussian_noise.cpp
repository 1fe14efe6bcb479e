// GaussianNoise: whitening by L⁻¹ (checked against a dense solve), and
// copies that share one Σ and L by a count in the data — through copies,
// moves, self-assignment and threads, the data outlives every holder and
// is freed once (AddressSanitizer in scripts/test checks the second half).
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <thread>
#include <vector>

#include "gssm/core/error.h"
#include "gssm/core/gaussian.h"

using gssm::GaussianNoise;

namespace {
Eigen::MatrixXd spd3() {
  Eigen::MatrixXd S(3, 3);
  S << 4, 1, 0.5, 1, 3, 0.2, 0.5, 0.2, 2;
  return S;
}
}  // namespace

TEST(GaussianNoise, WhitensByTheCholeskyFactor) {
  const GaussianNoise n(spd3());
  const Eigen::Vector3d v(1.0, -2.0, 0.5);
  const Eigen::VectorXd expected = n.sqrtCovariance().triangularView<Eigen::Lower>().solve(v);
  EXPECT_LT((n.whiten(v) - expected).norm(), 1e-14);
  EXPECT_NEAR(n.whiten(v).squaredNorm(), v.dot(spd3().ldlt().solve(v)), 1e-12);  // the Mahalanobis norm
  EXPECT_LT((n.sqrtCovariance() * n.sqrtCovariance().transpose() - spd3()).norm(), 1e-12);
  EXPECT_THROW(GaussianNoise(Eigen::MatrixXd::Zero(2, 2)), gssm::NumericalError);
  EXPECT_EQ(GaussianNoise().dim(), 0);
}

TEST(GaussianNoise, CopiesShareOneDataThatOutlivesEveryHolder) {
  std::vector<GaussianNoise> held;
  {
    GaussianNoise a(spd3());
    GaussianNoise b = a;             // copy
    GaussianNoise c = std::move(b);  // move: b stays valid
    EXPECT_EQ(b.dim(), 3);
    EXPECT_EQ(&c.covariance(), &a.covariance());  // one Σ for all
    const GaussianNoise& same = a;
    a = same;  // self-assignment
    GaussianNoise d;
    d = c;  // replaces the default's shared empty data
    EXPECT_EQ(&d.sqrtCovariance(), &a.sqrtCovariance());
    for (int i = 0; i < 100; ++i) held.push_back(i % 2 ? a : d);
  }  // a, b, c, d gone: the vector's copies still hold the data
  EXPECT_EQ(held.back().dim(), 3);
  // Threads copying and dropping one noise at once: the count is atomic.
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&held] {
      for (int i = 0; i < 20000; ++i) {
        GaussianNoise copy = held[static_cast<std::size_t>(i % 100)];
        GaussianNoise other;
        other = copy;
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_LT((held.front().covariance() - spd3()).norm(), 1e-15);
  held.clear();  // the last holders: the data is freed here, once
}
