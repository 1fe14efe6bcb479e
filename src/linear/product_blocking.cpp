// Eigen blocks a large matrix product by the CPU's cache sizes, which it
// reads at run time, and the blocking sets the order of the product's sums.
// On the GNSS/INS drive that order alone moved the batch's sds by up to 4 %
// between two CPUs (an AMD Zen 3 and a Zen 5: L1 32 and 48 KiB), the
// information matrix being that stiff. Fixed sizes, set when the library
// loads, make the results independent of the machine's caches
// (docs/DESIGN.md §11). They are process-wide: a program that sets its own
// after loading gssm gets its own blocking, and gssm with it.
#include <Eigen/Core>

namespace gssm::internal {
namespace {

struct PinnedProductBlocking {
  PinnedProductBlocking() {
    constexpr std::ptrdiff_t kL1 = 48 * 1024, kL2 = 1024 * 1024, kL3 = 32 * 1024 * 1024;  // a current server core's
    Eigen::setCpuCacheSizes(kL1, kL2, kL3);
  }
};

const PinnedProductBlocking kPinnedAtLoad;

}  // namespace
}  // namespace gssm::internal
