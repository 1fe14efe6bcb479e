// χ² quantiles for the consistency verdicts: against values tabulated to 17
// digits with an independent arbitrary-precision inversion (mpmath, 40
// digits), against the closed form of 2 degrees of freedom, and the CDF
// against the closed form of 1 degree of freedom (erf).
#include <gtest/gtest.h>

#include <cmath>

#include "gssm/analysis/chi_square.h"
#include "gssm/core/error.h"

using namespace gssm;

TEST(ChiSquare, QuantilesEqualTabulatedValues) {
  struct Row {
    double dof, p, x;
  };
  // mpmath.findroot on gammainc(k/2, 0, x/2, regularized=True) − p, 40 digits.
  const Row table[] = {{1, 0.025, 0.00098206911717525591},  {1, 0.975, 5.023886187314889},
                       {1, 1e-6, 1.5707963267957191e-12},   {1, 0.999999, 23.928126976934829},
                       {2, 0.5, 1.3862943611198906},        {3, 0.025, 0.21579528262389787},
                       {10, 0.05, 3.94029913611906},        {10, 0.95, 18.307038053275147},
                       {100, 0.99, 135.80672317102678},     {57, 0.999999, 122.79130136963103},
                       {1e6, 0.025, 997230.0871432901},     {1e6, 0.975, 1002773.701467926},
                       {1e6, 1e-6, 993292.0337373913}};
  for (const Row& r : table)
    EXPECT_NEAR(chiSquareQuantile(r.p, r.dof), r.x, 1e-9 * r.x) << "dof " << r.dof << ", p " << r.p;
}

TEST(ChiSquare, TwoDegreesOfFreedomMatchTheClosedFormAcrossTheRange) {
  // χ²₂ is exponential: x = −2 ln(1 − p).
  for (double p = 1e-6; p < 1; p = p < 0.5 ? p * 3 : 1 - (1 - p) / 3) {
    if (p > 1 - 1e-6) break;
    const double x = -2 * std::log1p(-p);
    EXPECT_NEAR(chiSquareQuantile(p, 2), x, 1e-9 * x) << p;
  }
}

TEST(ChiSquare, CdfOfOneDegreeMatchesErfAndInvertsTheQuantile) {
  for (double x : {1e-10, 1e-4, 0.3, 1.0, 3.84, 10.0, 30.0}) {
    EXPECT_NEAR(chiSquareCdf(x, 1), std::erf(std::sqrt(x / 2)), 1e-14) << x;
    EXPECT_NEAR(regularizedGammaQ(0.5, x / 2), std::erfc(std::sqrt(x / 2)), 1e-13 * std::erfc(std::sqrt(x / 2))) << x;
  }
  for (double dof : {1.0, 4.0, 33.0, 1000.0, 1e6})
    for (double p : {1e-6, 0.01, 0.3, 0.5, 0.9, 0.999999})
      EXPECT_NEAR(chiSquareCdf(chiSquareQuantile(p, dof), dof), p, 1e-11 * std::min(p, 1 - p) + 1e-15) << dof << " " << p;
}

TEST(ChiSquare, BadArgumentsAreNamed) {
  EXPECT_THROW(chiSquareQuantile(0, 1), InvalidArgument);
  EXPECT_THROW(chiSquareQuantile(1, 1), InvalidArgument);
  EXPECT_THROW(chiSquareQuantile(0.5, 0), InvalidArgument);
  EXPECT_THROW(chiSquareQuantile(std::nan(""), 3), InvalidArgument);
}
