#pragma once
// Internal: where the Bayes tree engine keeps the variable-size parts of its
// factor slots and cliques — keys and matrices, one record each — in 8-byte
// words, in large chunks, addressed by a 32-bit word index. A full-history
// run keeps one slot per factor and one clique per variable; as Eigen
// matrices and key lists each of their four matrices was a heap block with
// a 24-byte header and 8–16 bytes of malloc's own, about a fifth of the
// run's memory (docs/DESIGN.md §6).
//
// Records are recycled by exact size (a fixed-lag update frees and
// allocates the same few shapes every step); chunks are never given back
// while the engine lives. An index, not a pointer, names a record, so a copy
// of the store (an engine copied for a line search, a user's copy) is valid
// for the copy's records with the same indices.
#include <Eigen/Core>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

#include "gssm/core/key.h"

namespace gssm::internal {

class RecordStore {
 public:
  using Ref = std::uint32_t;  ///< a record's first word
  static constexpr int kChunkShift = 16;  ///< 64 Ki words (512 KiB) a chunk
  static constexpr std::size_t kChunkWords = std::size_t{1} << kChunkShift;

  RecordStore() = default;
  RecordStore(const RecordStore& o) { copyFrom(o); }
  RecordStore& operator=(const RecordStore& o) {
    if (this != &o) {
      RecordStore copy(o);
      *this = std::move(copy);
    }
    return *this;
  }
  RecordStore(RecordStore&&) noexcept = default;
  RecordStore& operator=(RecordStore&&) noexcept = default;

  /// A record of `words` words (> 0): a recycled one of that size if any.
  /// Throws std::bad_alloc when memory or the 32-bit index space runs out.
  Ref allocate(std::size_t words) {
    if (words < free_.size() && !free_[words].empty()) {
      const Ref r = free_[words].back();
      free_[words].pop_back();
      return r;
    }
    if (words >= free_.size()) {
      auto it = big_free_.find(words);
      if (it != big_free_.end() && !it->second.empty()) {
        const Ref r = it->second.back();
        it->second.pop_back();
        return r;
      }
    }
    return fresh(words);
  }
  /// Gives a record of `words` words back for reuse; its contents are dead.
  void release(Ref r, std::size_t words) {
    if (words == 0) return;
    if (words < kSmallSizes) {
      if (words >= free_.size()) free_.resize(words + 1);
      free_[words].push_back(r);
    } else {
      big_free_[words].push_back(r);
    }
  }

  /// Record r's words from `offset` on, as doubles or keys (a record is
  /// contiguous: offsets never leave it).
  double* doubles(Ref r, std::size_t offset = 0) { return reinterpret_cast<double*>(word(r) + offset); }
  const double* doubles(Ref r, std::size_t offset = 0) const {
    return reinterpret_cast<const double*>(word(r) + offset);
  }
  Key* keys(Ref r) { return reinterpret_cast<Key*>(word(r)); }
  const Key* keys(Ref r) const { return reinterpret_cast<const Key*>(word(r)); }

  /// Words allocated from the chunks (in use or on a free list).
  std::size_t wordsUsed() const { return top_; }

 private:
  static_assert(sizeof(Key) == 8 && std::is_trivially_copyable<Key>::value, "a key is one word");
  struct alignas(8) Word {
    unsigned char bytes[8];
  };
  static constexpr std::size_t kSmallSizes = 4096;  // sizes with a free list in an array; larger in a map

  Word* word(Ref r) const { return chunks_[r >> kChunkShift].get() + (r & (kChunkWords - 1)); }

  Ref fresh(std::size_t words) {
    std::size_t offset = top_ & (kChunkWords - 1);
    if (words > kChunkWords) {
      // A record larger than a chunk gets a run of chunk indices of its own,
      // one block of memory held by the first.
      if (offset != 0) leaveTail(kChunkWords - offset);
      const std::size_t n = (words + kChunkWords - 1) / kChunkWords;
      reserveIndex(n * kChunkWords);
      const Ref r = static_cast<Ref>(top_);
      chunks_.emplace_back(new Word[n * kChunkWords]);
      for (std::size_t i = 1; i < n; ++i) chunks_.emplace_back();
      top_ += n * kChunkWords;
      return r;
    }
    if (offset != 0 && offset + words > kChunkWords) {
      leaveTail(kChunkWords - offset);
      offset = 0;
    }
    if (offset == 0) {
      reserveIndex(kChunkWords);
      chunks_.emplace_back(new Word[kChunkWords]);
    }
    const Ref r = static_cast<Ref>(top_);
    top_ += words;
    return r;
  }
  // The end of a chunk too short for a record goes on the free list of its size.
  void leaveTail(std::size_t words) {
    release(static_cast<Ref>(top_), words);
    top_ += words;
  }
  void reserveIndex(std::size_t words) const {
    if (top_ + words > (std::size_t{1} << 32)) throw std::bad_alloc();  // 32 GiB of records
  }
  void copyFrom(const RecordStore& o) {
    top_ = o.top_;
    free_ = o.free_;
    big_free_ = o.big_free_;
    chunks_.reserve(o.chunks_.size());
    for (std::size_t i = 0; i < o.chunks_.size(); ++i) {
      if (!o.chunks_[i]) {
        chunks_.emplace_back();
        continue;
      }
      std::size_t n = 1;  // chunks this block spans (a large record's run)
      while (i + n < o.chunks_.size() && !o.chunks_[i + n]) ++n;
      const std::size_t words = std::min(n * kChunkWords, top_ - i * kChunkWords);
      chunks_.emplace_back(new Word[n * kChunkWords]);
      std::memcpy(static_cast<void*>(chunks_.back().get()), o.chunks_[i].get(), words * sizeof(Word));
    }
  }

  std::vector<std::unique_ptr<Word[]>> chunks_;
  std::size_t top_ = 0;                                 // next fresh word
  std::vector<std::vector<Ref>> free_;                  // recycled records by size
  std::map<std::size_t, std::vector<Ref>> big_free_;    // of kSmallSizes words or more
};

}  // namespace gssm::internal
