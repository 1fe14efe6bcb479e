// The inline-then-heap lists of the Bayes tree (slot ids, keys) behave as a
// std::vector under the operations the engine uses, across the inline/heap
// boundary, through copies and moves.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "gssm/core/key.h"
#include "solvers/small_list.h"

using gssm::Key;
using gssm::internal::SmallIntList;
using gssm::internal::SmallList;

namespace {
template <class List, class T>
void expectSame(const List& a, const std::vector<T>& b, int step) {
  ASSERT_EQ(a.size(), b.size()) << "step " << step;
  EXPECT_EQ(a.empty(), b.empty());
  EXPECT_TRUE(a.toVector() == b) << "step " << step;
  EXPECT_TRUE(a == b);
  for (std::size_t i = 0; i < b.size(); ++i) EXPECT_TRUE(a[i] == b[i]);
  if (!b.empty()) {
    EXPECT_TRUE(a.front() == b.front() && a.back() == b.back());
  }
}

template <class List, class T, class Make>
void randomOperations(Make&& make) {
  std::mt19937 rng(5);
  List list;
  std::vector<T> ref;
  for (int step = 0; step < 5000; ++step) {
    switch (rng() % 8) {
      case 0: case 1: case 2: case 3: {  // grow past the inline capacity often
        const T v = make(rng() % 7);
        list.push_back(v);
        ref.push_back(v);
        break;
      }
      case 4: {  // erase–remove of one value
        const T v = make(rng() % 7);
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
        List copy(list);
        expectSame(copy, ref, step);
        List assigned;
        assigned.assign(ref.begin(), ref.end());
        list = assigned;
        break;
      }
      case 7: {  // move out and back (the moved-from list is empty and reusable)
        List moved(std::move(list));
        expectSame(list, std::vector<T>{}, step);
        list.push_back(make(1));
        list = std::move(moved);
        expectSame(moved, std::vector<T>{}, step);
        break;
      }
    }
    expectSame(list, ref, step);
  }
}
}  // namespace

TEST(SmallList, IntsMatchAVectorThroughRandomPushEraseClearCopyAndMove) {
  randomOperations<SmallIntList, int>([](unsigned v) { return static_cast<int>(v); });
}

TEST(SmallList, KeysMatchAVectorThroughRandomPushEraseClearCopyAndMove) {
  randomOperations<SmallList<Key, 3>, Key>(
      [](unsigned v) { return v == 6 ? Key::constants() : Key::state(static_cast<std::int64_t>(v) - 3); });
}

TEST(SmallList, ResizeKeepsTheFirstEntriesAndFillsTheRest) {
  SmallList<double, 2> list;
  std::vector<double> ref;
  for (std::size_t n : {2u, 1u, 6u, 3u, 9u, 0u, 2u}) {
    list.resize(n, 7.5);
    ref.resize(n, 7.5);
    expectSame(list, ref, static_cast<int>(n));
    for (std::size_t i = 0; i < n; ++i) {
      list[i] = static_cast<double>(i) + 0.25 * static_cast<double>(n);  // written in place
      ref[i] = list[i];
    }
  }
}
