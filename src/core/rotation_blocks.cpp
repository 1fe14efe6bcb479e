#include "gssm/core/rotation_blocks.h"

#include "gssm/core/so3.h"

namespace gssm {

namespace {
// The blocks that lie in a vector of `size` at `offset`, as local indices.
template <class Fn>
void forEachBlock(const std::vector<int>& blocks, Eigen::Index size, int offset, Fn fn) {
  for (int b : blocks) {
    const Eigen::Index j = b - offset;
    if (j >= 0 && j + 3 <= size) fn(j);
  }
}
}  // namespace

bool hasRotationIn(const std::vector<int>& blocks, Eigen::Index size, int offset) {
  bool any = false;
  forEachBlock(blocks, size, offset, [&](Eigen::Index) { any = true; });
  return any;
}

void retractBlocks(Eigen::Ref<Eigen::VectorXd> x, const Eigen::Ref<const Eigen::VectorXd>& delta,
                   const std::vector<int>& blocks, int offset) {
  if (!hasRotationIn(blocks, x.size(), offset)) {
    x += delta;
    return;
  }
  // The blocks from their old φ; + on every other component.
  const Eigen::VectorXd phi = x;
  x += delta;
  forEachBlock(blocks, x.size(), offset, [&](Eigen::Index j) {
    // x ⊕ 0 = x exactly (Log(Exp(φ)) is φ only to rounding).
    x.segment<3>(j) = delta.segment<3>(j).isZero(0.0)
                          ? phi.segment<3>(j)
                          : so3::Log(so3::Exp(phi.segment<3>(j)) * so3::Exp(delta.segment<3>(j)));
  });
}

void localBlocks(const Eigen::Ref<const Eigen::VectorXd>& a, const Eigen::Ref<const Eigen::VectorXd>& b,
                 Eigen::VectorXd& r, const std::vector<int>& blocks, int offset, std::vector<Eigen::Matrix3d>* J_r_a,
                 std::vector<Eigen::Matrix3d>* J_r_b) {
  r = a - b;
  if (J_r_a) J_r_a->clear();
  if (J_r_b) J_r_b->clear();
  forEachBlock(blocks, r.size(), offset, [&](Eigen::Index j) {
    Eigen::Matrix3d Ja, Jb;
    r.segment<3>(j) = so3::minus(so3::Exp(a.segment<3>(j)), so3::Exp(b.segment<3>(j)), J_r_a ? &Ja : nullptr,
                                 J_r_b ? &Jb : nullptr);
    if (J_r_a) J_r_a->push_back(Ja);
    if (J_r_b) J_r_b->push_back(Jb);
  });
}

void premultiplyBlocks(Eigen::MatrixXd& J, const std::vector<Eigen::Matrix3d>& M, const std::vector<int>& blocks,
                       int offset) {
  std::size_t i = 0;
  forEachBlock(blocks, J.rows(), offset, [&](Eigen::Index j) {
    J.middleRows<3>(j) = (M[i++] * J.middleRows<3>(j)).eval();
  });
}

void postmultiplyBlocks(Eigen::MatrixXd& J, const std::vector<Eigen::Matrix3d>& M, const std::vector<int>& blocks,
                        int offset) {
  std::size_t i = 0;
  forEachBlock(blocks, J.cols(), offset, [&](Eigen::Index j) {
    J.middleCols<3>(j) = (J.middleCols<3>(j) * M[i++]).eval();
  });
}

std::vector<Eigen::Matrix3d> blockRightJacobians(const Eigen::Ref<const Eigen::VectorXd>& delta,
                                                 const std::vector<int>& blocks, int offset) {
  std::vector<Eigen::Matrix3d> out;
  forEachBlock(blocks, delta.size(), offset,
               [&](Eigen::Index j) { out.push_back(so3::rightJacobian(delta.segment<3>(j))); });
  return out;
}

void normalizeBlocks(Eigen::Ref<Eigen::VectorXd> x, const std::vector<int>& blocks, int offset) {
  forEachBlock(blocks, x.size(), offset, [&](Eigen::Index j) {
    if (x.segment<3>(j).norm() > M_PI) x.segment<3>(j) = so3::Log(so3::Exp(x.segment<3>(j)));
  });
}

}  // namespace gssm
