// The inline-then-heap int list of the Bayes tree behaves as a std::vector
// under the operations the engine uses, across the inline/heap boundary,
// through copies and moves.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "solvers/small_int_list.h"

using gssm::internal::SmallIntList;

namespace {
void expectSame(const SmallIntList& a, const std::vector<int>& b, int step) {
  ASSERT_EQ(a.size(), b.size()) << "step " << step;
  EXPECT_EQ(a.empty(), b.empty());
  EXPECT_EQ(a.toVector(), b) << "step " << step;
  for (std::size_t i = 0; i < b.size(); ++i) EXPECT_EQ(a[i], b[i]);
}
}  // namespace

TEST(SmallIntList, MatchesAVectorThroughRandomPushEraseClearCopyAndMove) {
  std::mt19937 rng(5);
  SmallIntList list;
  std::vector<int> ref;
  for (int step = 0; step < 5000; ++step) {
    switch (rng() % 8) {
      case 0: case 1: case 2: case 3: {  // grow past the inline capacity often
        const int v = static_cast<int>(rng() % 7);
        list.push_back(v);
        ref.push_back(v);
        break;
      }
      case 4: {  // erase–remove of one value
        const int v = static_cast<int>(rng() % 7);
        list.erase(std::remove(list.begin(), list.end(), v), list.end());
        ref.erase(std::remove(ref.begin(), ref.end(), v), ref.end());
        break;
      }
      case 5:
        if (rng() % 4 == 0) {
          list.clear();
          ref.clear();
        }
        break;
      case 6: {  // copy out and back, and assign from a range
        SmallIntList copy(list);
        expectSame(copy, ref, step);
        SmallIntList assigned;
        assigned.assign(ref.begin(), ref.end());
        list = assigned;
        break;
      }
      case 7: {  // move out and back (the moved-from list is empty and reusable)
        SmallIntList moved(std::move(list));
        expectSame(list, {}, step);
        list.push_back(1);
        list = std::move(moved);
        expectSame(moved, {}, step);
        break;
      }
    }
    expectSame(list, ref, step);
  }
}
