#pragma once
// Internal: the keys of a linear factor or of a clique's separator in 16
// bytes. A list of consecutive states, then at most the constants — a model
// factor's x_c(k), x_c(k+1), x_b, a measurement's x_c(k), x_b, a chain's
// separator x_c(k+1), x_b: every list of a radar run — is held as its first
// step and counts; any other in a heap array. A full-history run keeps three
// such lists per step (as inline arrays of three keys they took 32 bytes).
#include <cstdint>
#include <cstring>
#include <iterator>
#include <vector>

#include "gssm/core/key.h"

namespace gssm::internal {

class KeyList {
 public:
  KeyList() : first_(0) {}
  KeyList(const KeyList& o) : KeyList() { assign(o.begin(), o.end()); }
  KeyList(KeyList&& o) noexcept : KeyList() { take(o); }
  KeyList& operator=(const KeyList& o) {
    if (this != &o) assign(o.begin(), o.end());
    return *this;
  }
  KeyList& operator=(KeyList&& o) noexcept {
    if (this != &o) {
      release();
      take(o);
    }
    return *this;
  }
  ~KeyList() { release(); }

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  Key operator[](std::size_t i) const {
    if (on_heap_) return heap_[i];
    return i < states_ ? Key::state(first_ + static_cast<std::int64_t>(i)) : Key::constants();
  }
  Key front() const { return (*this)[0]; }

  // Walks the list with its form copied in: an inline list's keys are
  // made from words (a state's word steps by a fixed stride), no bit-field
  // packing per key.
  class const_iterator {
   public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = Key;
    using difference_type = std::ptrdiff_t;
    using pointer = void;
    using reference = Key;
    const_iterator(const KeyList& l, std::uint32_t i)
        : heap_(l.on_heap_ ? l.heap_ : nullptr),
          word_(l.on_heap_ ? 0 : Key::state(l.first_).word()),
          i_(i),
          states_(l.states_) {}
    Key operator*() const {
      if (heap_) return heap_[i_];
      return fromWord(i_ < states_ ? word_ + i_ * kStateStride : kConstantsWord);
    }
    const_iterator& operator++() {
      ++i_;
      return *this;
    }
    const_iterator operator++(int) {
      const_iterator old = *this;
      ++i_;
      return old;
    }
    friend bool operator==(const const_iterator& a, const const_iterator& b) { return a.i_ == b.i_; }
    friend bool operator!=(const const_iterator& a, const const_iterator& b) { return a.i_ != b.i_; }
    friend difference_type operator-(const const_iterator& a, const const_iterator& b) {
      return static_cast<difference_type>(a.i_) - static_cast<difference_type>(b.i_);
    }

   private:
    const Key* heap_;
    std::uint64_t word_;  // the first state's
    std::uint32_t i_, states_;
  };
  const_iterator begin() const { return {*this, 0}; }
  const_iterator end() const { return {*this, size_}; }

  /// Replaces the keys with [first, last) (no allocation when they are held
  /// inline, or fit the heap array it has).
  template <class It>
  void assign(It first, It last) {
    const auto n = static_cast<std::size_t>(std::distance(first, last));
    // Inline if consecutive states, then at most the constants, last.
    std::size_t states = 0;
    std::int64_t step0 = 0;
    bool inline_form = n <= kMaxInlineStates + 1;
    std::size_t i = 0;
    for (It it = first; inline_form && it != last; ++it, ++i) {
      const Key k = *it;
      if (k == Key::constants()) {
        inline_form = i + 1 == n;
      } else if (k.isConstants()) {
        inline_form = false;
      } else {
        if (states == 0) step0 = k.step;
        inline_form = k.step == step0 + static_cast<std::int64_t>(states) && states < kMaxInlineStates;
        ++states;
      }
    }
    if (inline_form) {
      release();
      first_ = step0;
      states_ = static_cast<std::uint8_t>(states);
      size_ = static_cast<std::uint32_t>(n);
      return;
    }
    if (!on_heap_ || capacity_ < n) {
      release();
      heap_ = static_cast<Key*>(::operator new(sizeof(Key) * n));
      capacity_ = n > 0xFFFF ? 0xFFFF : static_cast<std::uint16_t>(n);  // saturated: such a list is not reused
      on_heap_ = true;
    }
    i = 0;
    for (It it = first; it != last; ++it) heap_[i++] = *it;
    size_ = static_cast<std::uint32_t>(n);
  }
  std::vector<Key> toVector() const { return std::vector<Key>(begin(), end()); }

  friend bool operator==(const KeyList& a, const KeyList& b) { return equal(a, b); }
  friend bool operator!=(const KeyList& a, const KeyList& b) { return !equal(a, b); }
  friend bool operator==(const KeyList& a, const std::vector<Key>& b) { return equal(a, b); }
  friend bool operator!=(const KeyList& a, const std::vector<Key>& b) { return !equal(a, b); }

 private:
  static constexpr std::size_t kMaxInlineStates = 255;
  static Key fromWord(std::uint64_t w) {
    Key k;
    std::memcpy(static_cast<void*>(&k), &w, sizeof k);
    return k;
  }
  // Key's words: the constants', and how far apart consecutive states' are.
  static inline const std::uint64_t kConstantsWord = Key::constants().word();
  static inline const std::uint64_t kStateStride = Key::state(1).word() - Key::state(0).word();
  template <class List>
  static bool equal(const KeyList& a, const List& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a[i] != b[i]) return false;
    return true;
  }
  void release() {
    if (on_heap_) ::operator delete(heap_);
    on_heap_ = false;
    capacity_ = 0;
    first_ = 0;
    size_ = 0;
    states_ = 0;
  }
  void take(KeyList& o) {
    std::memcpy(static_cast<void*>(this), &o, sizeof(KeyList));
    o.on_heap_ = false;
    o.release();
  }

  union {
    std::int64_t first_;  // inline: the first state's step
    Key* heap_;
  };
  std::uint32_t size_ = 0;
  std::uint16_t capacity_ = 0;  // heap array's
  std::uint8_t states_ = 0;     // inline: the consecutive states; the constants follow if size_ is one more
  bool on_heap_ = false;
};

static_assert(sizeof(KeyList) == 16, "KeyList: 16 bytes");

}  // namespace gssm::internal
