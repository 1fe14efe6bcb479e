// The 16-byte key list of the Bayes tree holds any list of keys as a
// std::vector would: the inline form (consecutive states, then at most the
// constants) and the heap form, across reassignments between them, copies
// and moves.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "solvers/key_list.h"

using gssm::Key;
using gssm::internal::KeyList;

namespace {
void expectSame(const KeyList& a, const std::vector<Key>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(a.empty(), b.empty());
  EXPECT_TRUE(a == b) << what;
  EXPECT_FALSE(a != b);
  EXPECT_EQ(a.toVector(), b) << what;
  std::size_t i = 0;
  for (const auto& k : a) EXPECT_EQ(k, b[i++]) << what << " entry " << i;
  EXPECT_EQ(i, b.size());
  if (!b.empty()) {
    EXPECT_EQ(a.front(), b.front());
  }
}

std::string show(const std::vector<Key>& keys) {
  std::string s;
  for (const auto& k : keys) s += k.toString() + " ";
  return s;
}

// Lists of every shape the engine meets and some it does not.
std::vector<Key> randomKeys(std::mt19937& rng) {
  std::vector<Key> keys;
  const std::int64_t s = static_cast<std::int64_t>(rng() % 2000) - 1000;
  switch (rng() % 6) {
    case 0: keys = {Key::state(s), Key::state(s + 1), Key::constants()}; break;  // process
    case 1: keys = {Key::state(s), Key::constants()}; break;                     // measurement, separator
    case 2: keys = {Key::constants()}; break;
    case 3: keys = {Key::state(s), Key::state(s + 2)}; break;                    // not consecutive
    case 4: keys = {Key::constants(), Key::state(s)}; break;                     // constants not last
    case 5:
      for (unsigned i = rng() % 300; i-- > 0;) keys.push_back(Key::state(s + static_cast<std::int64_t>(i)));  // descending
      if (rng() % 2) keys.push_back(Key::constants());
      break;
  }
  if (rng() % 4 == 0) std::reverse(keys.begin(), keys.end());
  return keys;
}
}  // namespace

TEST(KeyList, HoldsAnyListAsAVectorDoes) {
  std::mt19937 rng(17);
  KeyList list;
  for (int step = 0; step < 3000; ++step) {
    const std::vector<Key> keys = randomKeys(rng);
    list.assign(keys.begin(), keys.end());
    expectSame(list, keys, show(keys));
    KeyList copy(list);
    expectSame(copy, keys, "copy of " + show(keys));
    KeyList moved(std::move(copy));
    expectSame(moved, keys, "move of " + show(keys));
    expectSame(copy, {}, "moved-from");
    copy = moved;
    expectSame(copy, keys, "copy-assigned");
    KeyList other;
    other = std::move(moved);
    expectSame(other, keys, "move-assigned");
    EXPECT_TRUE(other == list);
  }
}

TEST(KeyList, ConsecutiveStatesAndTheConstantsAreHeldInline) {
  // Steps at the ends of the range a checkpoint may carry, and 255 states.
  const std::int64_t big = (std::int64_t(1) << 62) - 3;
  std::vector<Key> keys{Key::state(big), Key::state(big + 1), Key::state(big + 2), Key::constants()};
  KeyList list;
  list.assign(keys.begin(), keys.end());
  expectSame(list, keys, "big steps");
  keys = {Key::state(-big), Key::constants()};
  list.assign(keys.begin(), keys.end());
  expectSame(list, keys, "negative steps");
  keys.clear();
  for (int i = 0; i < 256; ++i) keys.push_back(Key::state(i));  // one more state than inline holds
  list.assign(keys.begin(), keys.end());
  expectSame(list, keys, "256 states");
  keys.pop_back();
  list.assign(keys.begin(), keys.end());
  expectSame(list, keys, "255 states");
  const std::vector<Key> odd{Key(gssm::VariableKind::Constants, 5)};  // not the constants' key
  list.assign(odd.begin(), odd.end());
  expectSame(list, odd, "constants kind with a step");
}
