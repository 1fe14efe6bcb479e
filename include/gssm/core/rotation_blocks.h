#pragma once
// Rotation blocks of a state vector (docs/DESIGN.md §12): three components
// holding the rotation vector φ of R = Exp(φ), |φ| ≤ π. The estimators move
// them by R ⊕ δ = R·Exp(δ) and compare them by R_a ⊖ R_b = Log(R_bᵀR_a)
// (so3.h); every other component by + and −. A block is named by its first
// component's index in a stacked vector; `offset` is where the vector at
// hand starts in it (x_c: 0, x_b: n_c), and blocks outside it are skipped,
// as wrapAngles does with angles.
#include <Eigen/Core>
#include <vector>

namespace gssm {

/// Whether any block of `blocks` lies in a vector of `size` components at `offset`.
bool hasRotationIn(const std::vector<int>& blocks, Eigen::Index size, int offset = 0);

/// x ← x ⊕ δ: x + δ, and φ ← Log(Exp(φ)·Exp(δ_φ)) on each block.
void retractBlocks(Eigen::Ref<Eigen::VectorXd> x, const Eigen::Ref<const Eigen::VectorXd>& delta,
                   const std::vector<int>& blocks, int offset = 0);

/// r = a ⊖ b: a − b, and Log(Exp(φ_b)ᵀExp(φ_a)) on each block; with
/// J_r_a / J_r_b the 3×3 Jacobians of each block in order (Jr⁻¹(r) and
/// −Jr⁻¹(−r); the other components' are I and −I).
void localBlocks(const Eigen::Ref<const Eigen::VectorXd>& a, const Eigen::Ref<const Eigen::VectorXd>& b,
                 Eigen::VectorXd& r, const std::vector<int>& blocks, int offset = 0,
                 std::vector<Eigen::Matrix3d>* J_r_a = nullptr, std::vector<Eigen::Matrix3d>* J_r_b = nullptr);

/// J ← D·J, D the identity but for each block's 3×3 from `M` (in order) on its rows.
void premultiplyBlocks(Eigen::MatrixXd& J, const std::vector<Eigen::Matrix3d>& M, const std::vector<int>& blocks,
                       int offset = 0);
/// J ← J·D, D as above on the columns.
void postmultiplyBlocks(Eigen::MatrixXd& J, const std::vector<Eigen::Matrix3d>& M, const std::vector<int>& blocks,
                        int offset = 0);

/// Jr(δ_φ) of each block of δ, in order (the Jacobian of x ⊕ δ in δ there).
std::vector<Eigen::Matrix3d> blockRightJacobians(const Eigen::Ref<const Eigen::VectorXd>& delta,
                                                 const std::vector<int>& blocks, int offset = 0);

/// Each block's φ brought to |φ| ≤ π (the same rotation): for reported means.
void normalizeBlocks(Eigen::Ref<Eigen::VectorXd> x, const std::vector<int>& blocks, int offset = 0);

}  // namespace gssm
