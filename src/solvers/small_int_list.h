#pragma once
// Internal: a list of ints held inline up to kInline entries and on the heap
// beyond. A Bayes tree over a long chain keeps a few such lists per step
// (a clique's factors and children, a variable's factors); as std::vectors
// each was a heap block of its own, a tenth of a full-history run's memory.
#include <algorithm>
#include <cstdint>
#include <vector>

namespace gssm::internal {

class SmallIntList {
 public:
  static constexpr std::uint32_t kInline = 4;

  SmallIntList() = default;
  SmallIntList(const SmallIntList& o) { assign(o.begin(), o.end()); }
  SmallIntList(SmallIntList&& o) noexcept { take(o); }
  SmallIntList& operator=(const SmallIntList& o) {
    if (this != &o) assign(o.begin(), o.end());
    return *this;
  }
  SmallIntList& operator=(SmallIntList&& o) noexcept {
    if (this != &o) {
      release();
      take(o);
    }
    return *this;
  }
  ~SmallIntList() { release(); }

  int* begin() { return data(); }
  int* end() { return data() + size_; }
  const int* begin() const { return data(); }
  const int* end() const { return data() + size_; }
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  int operator[](std::size_t i) const { return data()[i]; }

  void push_back(int v) {
    if (size_ == capacity_) reserve(2 * capacity_);
    data()[size_++] = v;
  }
  /// Empties the list, keeping its storage.
  void clear() { size_ = 0; }
  /// Removes [first, last) (the erase–remove idiom).
  int* erase(int* first, int* last) {
    std::copy(last, end(), first);
    size_ -= static_cast<std::uint32_t>(last - first);
    return first;
  }
  template <class It>
  void assign(It first, It last) {
    size_ = 0;
    reserve(static_cast<std::uint32_t>(std::distance(first, last)));
    for (; first != last; ++first) data()[size_++] = *first;
  }
  std::vector<int> toVector() const { return std::vector<int>(begin(), end()); }

 private:
  bool onHeap() const { return capacity_ > kInline; }
  int* data() { return onHeap() ? heap_ : inline_; }
  const int* data() const { return onHeap() ? heap_ : inline_; }
  void reserve(std::uint32_t capacity) {
    if (capacity <= capacity_) return;
    int* grown = new int[capacity];
    std::copy(begin(), end(), grown);
    if (onHeap()) delete[] heap_;
    heap_ = grown;
    capacity_ = capacity;
  }
  void release() {
    if (onHeap()) delete[] heap_;
    capacity_ = kInline;
    size_ = 0;
  }
  // Takes o's entries (its heap block, or a copy of its inline ones); o is
  // left empty and inline.
  void take(SmallIntList& o) {
    size_ = o.size_;
    capacity_ = o.capacity_;
    if (o.onHeap()) heap_ = o.heap_;
    else std::copy(o.inline_, o.inline_ + o.size_, inline_);
    o.capacity_ = kInline;
    o.size_ = 0;
  }

  std::uint32_t size_ = 0, capacity_ = kInline;
  union {
    int inline_[kInline];
    int* heap_;
  };
};

}  // namespace gssm::internal
