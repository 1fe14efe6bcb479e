// The engine's record store keeps every live record's words as written
// through random allocations and releases of many sizes (a chain's few, a
// large clique's, records larger than a chunk), recycles released records
// by size (a fixed lag's steady state does not grow it), never lets a record
// cross a chunk, and a copy holds the same records independently.
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "solvers/record_store.h"

using gssm::Key;
using gssm::internal::RecordStore;

namespace {
struct Live {
  std::size_t words;
  std::uint32_t seed;
};
// Record r's words: a key first, then doubles, all derived from seed.
void fill(RecordStore& s, RecordStore::Ref r, const Live& l) {
  *s.keys(r) = Key::state(static_cast<std::int64_t>(l.seed));
  double* d = s.doubles(r, 1);
  for (std::size_t i = 1; i < l.words; ++i) d[i - 1] = l.seed * 1000.0 + static_cast<double>(i);
}
bool intact(const RecordStore& s, RecordStore::Ref r, const Live& l) {
  if (*s.keys(r) != Key::state(static_cast<std::int64_t>(l.seed))) return false;
  const double* d = s.doubles(r, 1);
  for (std::size_t i = 1; i < l.words; ++i)
    if (d[i - 1] != l.seed * 1000.0 + static_cast<double>(i)) return false;
  return true;
}
void expectAllIntact(const RecordStore& s, const std::map<RecordStore::Ref, Live>& live, int step) {
  for (const auto& kv : live) ASSERT_TRUE(intact(s, kv.first, kv.second)) << "record " << kv.first << " step " << step;
}
}  // namespace

TEST(RecordStore, LiveRecordsKeepTheirWordsThroughRandomAllocationsReleasesAndCopies) {
  std::mt19937 rng(5);
  RecordStore store;
  std::map<RecordStore::Ref, Live> live;
  std::uniform_int_distribution<int> op(0, 99);
  std::uint32_t seed = 1;
  for (int step = 0; step < 20000; ++step) {
    if (op(rng) < 55 || live.empty()) {
      const int kind = op(rng);
      const std::size_t words = kind < 90   ? 2 + static_cast<std::size_t>(op(rng) % 30)      // a chain's
                                : kind < 99 ? 500 + static_cast<std::size_t>(op(rng)) * 97  // a large clique's
                                            : RecordStore::kChunkWords + 1 + static_cast<std::size_t>(op(rng));
      const RecordStore::Ref r = store.allocate(words);
      ASSERT_EQ(live.count(r), 0u) << "record " << r << " handed out twice";
      // Within one chunk, or a large record's own run from a chunk's start.
      if (words <= RecordStore::kChunkWords)
        EXPECT_LE((r & (RecordStore::kChunkWords - 1)) + words, RecordStore::kChunkWords);
      else
        EXPECT_EQ(r & (RecordStore::kChunkWords - 1), 0u);
      live[r] = {words, seed++};
      fill(store, r, live[r]);
    } else {
      auto it = live.begin();
      std::advance(it, static_cast<long>(rng() % live.size()));
      store.release(it->first, it->second.words);
      live.erase(it);
    }
    if (step % 5000 == 4999) {
      expectAllIntact(store, live, step);
      // A copy is independent: overwriting the original leaves it as it was.
      const RecordStore copy(store);
      for (const auto& kv : live) *store.doubles(kv.first, 1) = -1.0;
      expectAllIntact(copy, live, step);
      for (const auto& kv : live) fill(store, kv.first, kv.second);
      RecordStore assigned;
      assigned = copy;
      expectAllIntact(assigned, live, step);
    }
  }
  expectAllIntact(store, live, 20000);
}

TEST(RecordStore, ReleasedRecordsAreReusedBySize) {
  RecordStore store;
  // A fixed lag's steady state: every step frees and allocates the same shapes.
  std::vector<std::pair<RecordStore::Ref, std::size_t>> window;
  for (int step = 0; step < 100; ++step)
    for (std::size_t words : {8u, 6u, 16u, 10u}) window.emplace_back(store.allocate(words), words);
  const std::size_t used = store.wordsUsed();
  for (int step = 0; step < 10000; ++step) {
    for (int i = 0; i < 4; ++i) {
      store.release(window.front().first, window.front().second);
      window.erase(window.begin());
    }
    for (std::size_t words : {8u, 6u, 16u, 10u}) window.emplace_back(store.allocate(words), words);
  }
  EXPECT_EQ(store.wordsUsed(), used);
  // The most recently released record of a size is the next one handed out.
  const RecordStore::Ref r = store.allocate(33);
  store.release(r, 33);
  EXPECT_EQ(store.allocate(33), r);
  EXPECT_NE(store.allocate(33), r);
}
